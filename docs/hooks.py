"""The documentation site's build hooks (MkDocs, ``hooks:`` in ``mkdocs.yml``).

What the site shows that no one writes by hand is made here, at every build:

- ``index.md``: the README itself, its links turned into the site's own (so the README and
  the site's first page are one text);
- ``reference/``: the node reference, one page per family, from the registry
  (:mod:`formgraph.language.catalogue`): a node added to ``nodes/`` appears with no page to
  edit, each with links to the manual pages and the example graphs that use it;
- ``gallery/``: a page per example graph in ``graphs/``, its picture (``docs/gallery/NAME.png``,
  made by ``python -m formgraph.viewer.gallery``; a test checks it is current), its params,
  the nodes it uses and its YAML;
- ``graphs/``: a copy of the example files (parts, inputs), so a manual page's link to
  ``../graphs/parts/ring.yaml`` works on the site as it does on GitHub.

Links in a manual page are written as a reader of the repository follows them
(``../graphs/lamp.yaml``, ``../README.md#the-studio``) and rewritten here: a graph with a
gallery page links to that page. The nav is ``mkdocs.yml``'s, with the reference's families
filled in (the gallery's cards lead to its pages) and any page of ``docs/`` it does not list
appended under "More topics", so a new page is on the site before anyone edits the nav.

The functions that make text are plain (no MkDocs import), and the tests call them; the
``on_*`` functions at the end are the MkDocs side.
"""

from __future__ import annotations

import logging
import posixpath
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

log = logging.getLogger("mkdocs.plugins.formgraph")

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GRAPHS = ROOT / "graphs"
MORE = "More topics"  # the nav section that takes pages mkdocs.yml does not list
REFERENCE, GALLERY = "reference/index.md", "gallery/index.md"

# a Markdown link or image target: ](target) or ](target "title")
LINK = re.compile(r"(\]\()([^)\s]+)((?:\s+\"[^\"]*\")?\))")


def example_graphs(graphs: Path = GRAPHS) -> list[Path]:
    """The example graphs the gallery shows: every ``graphs/*.yaml`` (not the parts)."""
    return sorted(graphs.glob("*.yaml"))


# ------------------------------------------------------------------------------ links


def rewrite_links(
    markdown: str, page: str, target: Callable[[str], str | None], *, base: str
) -> str:
    """Every relative link of ``markdown`` (a page at ``page``, whose links are relative to
    the repository folder ``base``) through ``target``: a repository path (``graphs/x.yaml``,
    ``docs/solids.md#a``) to a site path (``gallery/x.md``), or ``None`` to leave the link
    as it is. The result is relative to ``page``."""
    here = posixpath.dirname(page)

    def one(m: re.Match[str]) -> str:
        link = m.group(2)
        if re.match(r"^[a-z][a-z0-9+.-]*:", link) or link.startswith(("#", "/")):
            return m.group(0)  # a URL, an anchor on this page, or absolute
        path, _, anchor = link.partition("#")
        repo_path = posixpath.normpath(posixpath.join(base, path))
        site = target(repo_path)
        if site is None:
            return m.group(0)
        new = posixpath.relpath(site, here or ".") + (f"#{anchor}" if anchor else "")
        return m.group(1) + new + m.group(3)

    return LINK.sub(one, markdown)


def site_path(repo_path: str, gallery: set[str]) -> str | None:
    """Where a repository file is on the site: a page of docs/ is itself, README is the home
    page, an example graph its gallery page, any other file of graphs/ its copy; the folders
    graphs/ and nodes/ are the gallery and the node reference. None: not on the site."""
    if repo_path == "README.md":
        return "index.md"
    if repo_path == "graphs":  # the examples' folder: on the site, their gallery
        return GALLERY
    if repo_path == "nodes":  # the nodes' code: on the site, their reference
        return REFERENCE
    if repo_path.startswith("docs/"):
        return repo_path[len("docs/") :]
    if repo_path.startswith("graphs/"):
        name = repo_path[len("graphs/") :]
        if name.endswith(".yaml") and "/" not in name and name[:-5] in gallery:
            return f"gallery/{name[:-5]}.md"
        return repo_path
    return None


# ------------------------------------------------------------------------ the gallery


def _param_row(name: str, spec: Any) -> str:
    if not isinstance(spec, dict):
        spec = {"default": spec}
    cells = [spec.get(k, "") for k in ("default", "min", "max")]
    text = [f"`{c}`" if c != "" else "" for c in cells]
    doc = str(spec.get("doc", "")).replace("|", "\\|")
    choices = spec.get("choices")
    if choices:
        doc = (doc + "; " if doc else "") + "one of " + ", ".join(f"`{c}`" for c in choices)
    return f"| `{name}` | {' | '.join(text)} | {doc} |"


def gallery_page(path: Path, node_link: Callable[[str], str | None]) -> str:
    """A gallery page: an example graph's picture, what it makes, its params, the nodes it
    uses (linked by ``node_link(type)``) and its YAML."""
    text = path.read_text(encoding="utf-8")
    data = yaml.safe_load(text) or {}
    name = path.stem
    lines = [f"# {name}", "", " ".join(str(data.get("description", "")).split()), ""]
    lines += [f"![{name}]({name}.png)", ""]
    lines += [
        "Run it, draw it, change it:",
        "",
        "```sh",
        f"formgraph run graphs/{name}.yaml --out out/{name}",
        f"formgraph view graphs/{name}.yaml --screenshot {name}.png",
        f"formgraph serve graphs/{name}.yaml",
        "```",
        "",
    ]
    params = data.get("params") or {}
    if params:
        lines += ["| param | default | min | max | what it is |", "|---|---|---|---|---|"]
        lines += [_param_row(k, v) for k, v in params.items()]
        lines.append("")
    types = sorted({str(n.get("type")) for n in (data.get("nodes") or {}).values()})
    used = []
    for t in types:
        link = node_link(t)
        if link is not None:
            used.append(f"[`{t}`]({link})")
        elif t.endswith((".yaml", ".yml")):
            used.append(f"[`{t}`](../graphs/{t}) (a subgraph)")
        else:
            used.append(f"`{t}`")
    lines += ["Nodes: " + ", ".join(used) + ".", ""]
    lines += [f"`graphs/{name}.yaml`:", "", "```yaml", text.rstrip("\n"), "```", ""]
    return "\n".join(lines)


def gallery_index(paths: list[Path]) -> str:
    """The gallery's first page: a card per example, its picture and what it makes."""
    lines = [
        "---",
        "hide: [toc]",
        "---",
        "",
        "# Gallery",
        "",
        "Every graph in `graphs/`, each evaluated by the tests and drawn off screen by the "
        "project's own viewer (`python -m formgraph.viewer.gallery` redraws them all into "
        "`docs/gallery/`; a test checks that each picture is of its graph as it is now). Red "
        "is the back of a face: the inside of the vase and of the tube's open end, one side "
        "of Enneper's surface, the top of the canopy, whose faces point down (a loft's "
        "normals follow the order and direction of its curves).",
        "",
        '<div class="grid cards" markdown>',
        "",
    ]
    for path in paths:
        data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
        words = " ".join(str(data.get("description", "")).split())
        first = words.split(". ")[0].rstrip(".") + "." if words else ""
        lines += [
            f"-   [![{path.stem}]({path.stem}.png)]({path.stem}.md)",
            "",
            f"    **[{path.stem}]({path.stem}.md)**: {first}",
            "",
        ]
    lines += ["</div>", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------- cross-references


def mentions(pages: dict[str, str], names: list[str]) -> dict[str, list[str]]:
    """For each node type name, the pages (site paths) whose text names it in code."""
    out: dict[str, list[str]] = {n: [] for n in names}
    for page, text in sorted(pages.items()):
        found = set(re.findall(r"`([a-z_]+\.[a-z_0-9]+)[(`]", text))
        for n in names:
            if n in found:
                out[n].append(page)
    return out


def _title(text: str, fallback: str) -> str:
    m = re.search(r"^#\s+(.+?)\s*$", text, flags=re.M)
    return m.group(1).strip("`") if m else fallback


# -------------------------------------------------------------------------------- MkDocs


def _nav_files(nav: Any) -> set[str]:
    if isinstance(nav, str):
        return {nav}
    if isinstance(nav, dict):
        return set().union(*(_nav_files(v) for v in nav.values())) if nav else set()
    if isinstance(nav, list):
        return set().union(*(_nav_files(v) for v in nav)) if nav else set()
    return set()


def _expand(nav: list[Any], index: str, children: list[Any]) -> None:
    """Turn the nav entry that names ``index`` into a section: the index, then children."""
    for i, item in enumerate(nav):
        if isinstance(item, dict):
            for title, value in item.items():
                if value == index:
                    nav[i] = {title: [index, *children]}
                elif isinstance(value, list):
                    _expand(value, index, children)


def on_config(config: Any) -> Any:
    from formgraph.language.catalogue import families

    nav = config.nav
    if nav is None:
        return config
    _expand(nav, REFERENCE, [{f: f"reference/{f}.md"} for f in families()])
    listed = _nav_files(nav)
    skipped = {"speed-table.md"}  # included by speed.md, not a page of its own in the nav
    new = [
        p.relative_to(DOCS).as_posix()
        for p in sorted(DOCS.glob("*.md"))
        if p.relative_to(DOCS).as_posix() not in listed | skipped
    ]
    if new:
        section = next((s for s in nav if isinstance(s, dict) and MORE in s), None)
        if section is None:
            section = {MORE: []}
            nav.append(section)
        for page in new:
            log.info("%s is not in mkdocs.yml's nav: shown under %r", page, MORE)
            section[MORE].append(page)
    return config


def on_files(files: Any, config: Any) -> Any:
    from mkdocs.structure.files import File, InclusionLevel

    from formgraph.core.registry import node_types
    from formgraph.language.catalogue import families, family_markdown, index_markdown

    graphs = example_graphs()
    gallery = {p.stem for p in graphs}
    registry = node_types()

    def add(uri: str, content: str | bytes, in_nav: bool = True) -> None:
        inclusion = InclusionLevel.UNDEFINED if in_nav else InclusionLevel.NOT_IN_NAV
        files.append(File.generated(config, uri, content=content, inclusion=inclusion))

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    add("index.md", rewrite_links(readme, "index.md", lambda p: site_path(p, gallery), base=""))

    # who mentions which node: the manual pages, and the graphs that use it
    pages = {
        f.src_uri: Path(f.abs_src_path).read_text(encoding="utf-8")
        for f in files
        if f.src_uri.endswith(".md") and f.abs_src_path and f.src_uri != "speed-table.md"
    }
    titles = {uri: _title(text, uri) for uri, text in pages.items()}
    used_in = mentions(pages, list(registry))
    examples: dict[str, list[str]] = {n: [] for n in registry}
    for p in graphs:
        for n in (yaml.safe_load(p.read_text(encoding="utf-8")) or {}).get("nodes", {}).values():
            t = str(n.get("type")) if isinstance(n, dict) else ""
            if t in examples and p.stem not in examples[t]:
                examples[t].append(p.stem)

    def see_also(spec: Any) -> str:
        parts = []
        if used_in[spec.name]:
            links = ", ".join(f"[{titles[u]}](../{u})" for u in used_in[spec.name])
            parts.append(f"In the manual: {links}.")
        if examples[spec.name]:
            links = ", ".join(f"[{g}](../gallery/{g}.md)" for g in examples[spec.name])
            parts.append(f"Examples: {links}.")
        return " ".join(parts)

    add(REFERENCE, index_markdown())
    for family in families():
        manual = sorted(
            {u for s in families()[family] for u in used_in[s.name] if u.startswith("family-")}
        )
        intro = (
            "The manual: " + ", ".join(f"[{titles[u]}](../{u})" for u in manual) + "."
            if manual
            else ""
        )
        add(f"reference/{family}.md", family_markdown(family, see_also, intro))

    def node_link(t: str) -> str | None:
        if t in registry:
            return f"../reference/{registry[t].family}.md#{t}"
        return None

    add(GALLERY, gallery_index(graphs))
    for p in graphs:
        add(f"gallery/{p.stem}.md", gallery_page(p, node_link), in_nav=False)  # the cards lead
        if not (DOCS / "gallery" / f"{p.stem}.png").is_file():
            log.warning(
                "graphs/%s.yaml has no picture docs/gallery/%s.png: "
                "run python -m formgraph.viewer.gallery %s",
                p.stem,
                p.stem,
                p.stem,
            )
    for p in sorted(GRAPHS.rglob("*")):
        if p.is_file():
            add(p.relative_to(ROOT).as_posix(), p.read_bytes())
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    uri = page.file.src_uri
    if page.file.generated_by or uri == "index.md":
        return markdown  # made here, links already the site's
    gallery = {p.stem for p in example_graphs()}
    base = posixpath.join("docs", posixpath.dirname(uri))
    return rewrite_links(markdown, uri, lambda p: site_path(p, gallery), base=base)
