"""Render every example graph to a PNG and print the README's gallery table.

Run from the repository root::

    python -m formgraph.viewer.gallery            # graphs/*.yaml -> docs/gallery/NAME.png

It loops over whatever graphs are there; a graph that fails is reported on stderr, left
out of the table, and makes the exit code 1.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Entry", "main", "markdown_table", "render_gallery"]


@dataclass(frozen=True)
class Entry:
    """One rendered graph (or the error that stopped it)."""

    name: str
    graph: Path
    image: Path
    description: str = ""
    error: str | None = None


def render_gallery(
    graphs_dir: str | os.PathLike[str] = "graphs",
    out_dir: str | os.PathLike[str] = "docs/gallery",
    size: tuple[int, int] = (640, 480),
) -> list[Entry]:
    """Render the results of every ``graphs_dir/*.yaml`` to ``out_dir/NAME.png``."""
    from formgraph.core.errors import FormgraphError
    from formgraph.evaluation.graph import load

    from .entry import screenshot

    graphs = sorted(Path(graphs_dir).glob("*.yaml"))
    entries = []
    with tempfile.TemporaryDirectory(prefix="formgraph-gallery-") as scratch:
        for path in graphs:
            image = Path(out_dir) / f"{path.stem}.png"
            try:
                # exports are never drawn, but a graph must not write outside a scratch folder
                g = load(path, out_dir=scratch)
                # a mesh with a ``color`` attribute is drawn in its own colours
                screenshot(g, image, size=size, color="color")
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
    entries = render_gallery(args.graphs, args.out, (w, h))
    for e in entries:
        if e.error is not None:
            print(f"gallery: {e.name}: {e.error}", file=sys.stderr)
        else:
            print(f"gallery: wrote {e.image}", file=sys.stderr)
    sys.stdout.write(markdown_table(entries, args.base))
    return 1 if any(e.error is not None for e in entries) else 0


if __name__ == "__main__":
    sys.exit(main())
