"""Render the example graphs to the pictures of the documentation's gallery.

Run from the repository root::

    python -m formgraph.viewer.gallery              # graphs/*.yaml -> docs/gallery/NAME.png
    python -m formgraph.viewer.gallery vase lamp    # only these
    python -m formgraph.viewer.gallery --stale      # only those whose graph changed since

Each picture carries, in its PNG metadata, a digest of the files it was drawn from (the graph,
its subgraph files and the files it reads): :func:`stale` compares it with the files as they
are now, and a test fails when a graph in ``graphs/`` has no picture or an outdated one. A
graph that fails is reported on stderr, left out of the Markdown table printed on stdout, and
makes the exit code 1.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Entry", "main", "markdown_table", "render_gallery", "source_digest", "stale"]

# the PNG text chunk that holds the digest of the files a picture was drawn from
SOURCE_KEY = "formgraph-source"


@dataclass(frozen=True)
class Entry:
    """One rendered graph (or the error that stopped it)."""

    name: str
    graph: Path
    image: Path
    description: str = ""
    error: str | None = None


def source_digest(graph: str | os.PathLike[str]) -> str:
    """A digest of everything a graph's picture is drawn from: the graph file, the subgraph
    files it uses and the files its read nodes name (each by its path relative to the
    graph's folder and its bytes)."""
    from formgraph.evaluation.graph import load

    g = load(graph)
    folder = Path(graph).resolve().parent
    h = hashlib.sha256()
    for f in sorted({Path(p).resolve() for p in [*g.files, *g.input_files]}):
        h.update(os.path.relpath(f, folder).encode() + b"\0")
        h.update(hashlib.sha256(f.read_bytes()).digest())
    return h.hexdigest()


def picture_digest(image: str | os.PathLike[str]) -> str | None:
    """The source digest a gallery picture was drawn from (None: none recorded)."""
    from PIL import Image

    with Image.open(image) as im:
        return im.text.get(SOURCE_KEY) if hasattr(im, "text") else None


def stale(
    graphs_dir: str | os.PathLike[str] = "graphs",
    out_dir: str | os.PathLike[str] = "docs/gallery",
) -> list[str]:
    """The graphs of ``graphs_dir`` whose picture in ``out_dir`` is missing, or was drawn
    from other files than the graph's as they are now."""
    out = []
    for path in sorted(Path(graphs_dir).glob("*.yaml")):
        image = Path(out_dir) / f"{path.stem}.png"
        if not image.is_file() or picture_digest(image) != source_digest(path):
            out.append(path.stem)
    return out


def render_gallery(
    graphs_dir: str | os.PathLike[str] = "graphs",
    out_dir: str | os.PathLike[str] = "docs/gallery",
    size: tuple[int, int] = (640, 480),
    names: Sequence[str] | None = None,
) -> list[Entry]:
    """Render the results of every ``graphs_dir/*.yaml`` (or of those ``names``) to
    ``out_dir/NAME.png``, each with the digest of its sources in its metadata."""
    from PIL import Image, PngImagePlugin

    from formgraph.core.errors import FormgraphError
    from formgraph.evaluation.graph import load

    from .entry import screenshot

    graphs = sorted(Path(graphs_dir).glob("*.yaml"))
    if names is not None:
        graphs = [g for g in graphs if g.stem in set(names)]
    entries = []
    with tempfile.TemporaryDirectory(prefix="formgraph-gallery-") as scratch:
        for path in graphs:
            image = Path(out_dir) / f"{path.stem}.png"
            try:
                # exports are never drawn, but a graph must not write outside a scratch folder
                g = load(path, out_dir=scratch)
                drawn = Path(scratch) / f"{path.stem}.png"
                # a mesh with a ``color`` attribute is drawn in its own colours
                screenshot(g, drawn, size=size, color="color")
                info = PngImagePlugin.PngInfo()
                info.add_text(SOURCE_KEY, source_digest(path))
                image.parent.mkdir(parents=True, exist_ok=True)
                with Image.open(drawn) as im:
                    im.save(image, pnginfo=info, optimize=True)
            except FormgraphError as exc:
                entries.append(Entry(path.stem, path, image, error=str(exc)))
                continue
            description = " ".join(g.description.split())
            entries.append(Entry(path.stem, path, image, description))
    return entries


def markdown_table(entries: Sequence[Entry], base: str | os.PathLike[str] = ".") -> str:
    """A Markdown table: graph (linked), what it makes, picture; paths relative to ``base``."""

    def rel(p: Path) -> str:
        return Path(os.path.relpath(p, base)).as_posix()

    rows = ["| Graph | What it makes | Picture |", "| --- | --- | --- |"]
    for e in entries:
        if e.error is not None:
            continue
        text = (e.description or "").replace("|", "\\|")
        rows.append(f"| [{e.name}]({rel(e.graph)}) | {text} | ![{e.name}]({rel(e.image)}) |")
    return "\n".join(rows) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m formgraph.viewer.gallery",
        description="Render every graph in a folder to PNG and print a Markdown table.",
    )
    ap.add_argument("names", nargs="*", help="only these graphs (their file names, no .yaml)")
    ap.add_argument("--stale", action="store_true", help="only graphs whose picture is stale")
    ap.add_argument("--graphs", default="graphs", help="folder of *.yaml graphs (graphs)")
    ap.add_argument("--out", default="docs/gallery", help="folder for the PNGs (docs/gallery)")
    ap.add_argument("--size", default="640x480", metavar="WxH", help="image size (640x480)")
    ap.add_argument("--base", default=".", help="the folder the table's links start from")
    args = ap.parse_args(argv)
    try:
        w, h = (int(x) for x in args.size.lower().split("x"))
    except ValueError:
        ap.error(f"--size takes WIDTHxHEIGHT, e.g. 640x480, got {args.size!r}")
    if not Path(args.graphs).is_dir():
        print(f"gallery: no folder {args.graphs!r}", file=sys.stderr)
        return 1
    names = args.names or None
    if args.stale:
        names = [n for n in stale(args.graphs, args.out) if names is None or n in names]
    unknown = sorted(set(names or ()) - {p.stem for p in Path(args.graphs).glob("*.yaml")})
    if unknown:
        print(f"gallery: no graph {', '.join(unknown)} in {args.graphs}", file=sys.stderr)
        return 1
    entries = render_gallery(args.graphs, args.out, (w, h), names)
    for e in entries:
        if e.error is not None:
            print(f"gallery: {e.name}: {e.error}", file=sys.stderr)
        else:
            print(f"gallery: wrote {e.image}", file=sys.stderr)
    sys.stdout.write(markdown_table(entries, args.base))
    return 1 if any(e.error is not None for e in entries) else 0


if __name__ == "__main__":
    sys.exit(main())
