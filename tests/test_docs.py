"""The manual stays true: every YAML block of README.md and docs/*.md is a graph that passes
the check or an excerpt of an example that does, its Python blocks run, its links lead
somewhere, every example has a current picture, and the pages made at build time
(docs/hooks.py: the node reference, the gallery, the README as the home page) hold what
they should. The site itself is built by .ci/run (``mkdocs build --strict``)."""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
import yaml

import formgraph as fg
from formgraph.core.registry import node_types
from formgraph.language import catalogue
from formgraph.viewer import gallery

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]

_spec = importlib.util.spec_from_file_location("formgraph_docs_hooks", DOCS / "hooks.py")
hooks = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(hooks)


def code_blocks(lang: str) -> list[tuple[str, int, str]]:
    """(page, line, text) of every ``lang`` block of the README and docs/*.md."""
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for m in re.finditer(rf"^```{lang}\n(.*?)^```", text, flags=re.S | re.M):
            line = text.count("\n", 0, m.start()) + 1
            out.append((page.relative_to(ROOT).as_posix(), line, m.group(1)))
    return out


def example_nodes() -> dict[str, list[dict]]:
    """Every node and param of every graph file under graphs/, by name: what an excerpt
    may quote."""
    found: dict[str, list] = {}
    for path in sorted((ROOT / "graphs").rglob("*.yaml")):
        data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
        for section in ("nodes", "params"):
            for name, value in (data.get(section) or {}).items():
                found.setdefault(f"{section}:{name}", []).append(value)
    return found


SHIPPED = {n: s for n, s in node_types().items() if s.func.__module__.startswith("formgraph.")}


# ------------------------------------------------------------------------ YAML blocks


def _is_graph(data: object) -> bool:
    return isinstance(data, dict) and bool({"formgraph", "nodes", "params"} & set(data))


@pytest.mark.parametrize(
    "page,line,block", [pytest.param(*b, id=f"{b[0]}:{b[1]}") for b in code_blocks("yaml")]
)
def test_every_yaml_block_is_a_checked_graph_or_an_excerpt_of_an_example(page, line, block):
    where = f"{page}:{line}"
    data = yaml.safe_load(block)  # a block that is not YAML fails here
    if isinstance(data, dict) and "formgraph" in data:
        fg.Graph.from_text(block, file=where)  # a whole graph: the check passes
        return
    if _is_graph(data):
        try:  # a graph but for its header
            fg.Graph.from_text("formgraph: 1\n" + block, file=where)
            return
        except fg.GraphError:
            pass  # then an excerpt: its nodes and params quote an example's
    assert isinstance(data, dict), f"{where}: a YAML block must be a mapping"
    quoted = {}
    if _is_graph(data):
        quoted.update({f"nodes:{k}": v for k, v in (data.get("nodes") or {}).items()})
        quoted.update({f"params:{k}": v for k, v in (data.get("params") or {}).items()})
    else:
        quoted.update({f"nodes:{k}": v for k, v in data.items()})
    examples = example_nodes()
    wrong = [k for k, v in quoted.items() if v not in examples.get(k, [])]
    assert not wrong, (
        f"{where}: {', '.join(wrong)} quote(s) no graph of graphs/ as written there: "
        "write a whole graph, or copy the nodes from an example"
    )


def test_the_excerpt_rule_fails_for_the_right_reason():
    examples = example_nodes()
    assert {"type": "nurbs.circle", "radius": "=hole_radius"} in examples["nodes:hole"]
    assert {"type": "nurbs.circle", "radius": 3} not in examples["nodes:hole"]


def test_every_node_example_is_yaml_naming_the_node_and_its_ports():
    for name, spec in SHIPPED.items():
        _, sections = catalogue._doc_sections(spec.doc)
        example = sections.get("Example")
        if example is None:
            continue
        code = re.search(r"``(.*?)``", " ".join(example.split())).group(1)
        ((_, node),) = yaml.safe_load("{" + code + "}").items()
        assert node["type"] == name, name
        assert set(node) - {"type", "repeat", "simulate"} <= set(spec.inputs), name


# ------------------------------------------------------------------------ Python blocks


def _python_block(page: str, marker: str) -> str:
    (code,) = [b for p, _, b in code_blocks("python") if p == page and marker in b]
    return code


def test_the_embedding_page_runs(tmp_path):
    code = _python_block("docs/python.md", "g.save(")
    shutil.copytree(ROOT / "graphs", tmp_path / "graphs")
    run = [sys.executable, "-c", "import formgraph as fg\n" + code]
    r = subprocess.run(run, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out" / "tube.stl").is_file()
    assert (
        fg.load(tmp_path / "copy.yaml").params == fg.load(ROOT / "graphs/spiral_tube.yaml").params
    )


def test_the_solids_page_example_runs_to_watertight_solids(tmp_path):
    ((_, _, example),) = [b for b in code_blocks("yaml") if "A pot, as a capped solid" in b[2]]
    g = fg.Graph.from_text(example, out_dir=tmp_path)
    for node in ("solid", "shell", "holes"):
        assert g.evaluate(node).is_watertight, node
    size = g.evaluate("size")
    assert size.watertight and size.volume == pytest.approx(g.evaluate("solid").volume)
    assert g.evaluate("holes").volume < g.evaluate("shell").volume
    g.evaluate_all()
    assert (tmp_path / "pot.stl").is_file()


# -------------------------------------------------------------------------------- links


def test_every_relative_link_of_the_manual_leads_to_a_file():
    # as GitHub follows them; the strict site build checks them again, anchors too
    generated = ("reference/", "gallery/")
    for page in PAGES[1:]:
        text = re.sub(r"^```.*?^```", "", page.read_text(encoding="utf-8"), flags=re.S | re.M)
        for link in re.findall(r"\]\(([^)\s]+)\)", text):
            path = link.partition("#")[0]
            if not path or re.match(r"^[a-z]+:", link) or path.startswith(generated):
                continue
            assert (page.parent / path).exists(), f"{page.name}: {link}"


def test_links_are_turned_into_the_sites_own():
    gallery_names = {"lamp", "vase"}

    def site(p: str) -> str | None:
        return hooks.site_path(p, gallery_names)

    text = (
        "[a](../graphs/lamp.yaml) [b](../graphs/parts/ring.yaml) [c](../README.md#the-studio) "
        "[d](solids.md#repair) [e](https://x.org/a.md) [f](#here) ![g](gallery/vase.png) "
        "[h](../engine/core/registry.py)"
    )
    out = hooks.rewrite_links(text, "cutting.md", site, base="docs")
    assert out == (
        "[a](gallery/lamp.md) [b](graphs/parts/ring.yaml) [c](index.md#the-studio) "
        "[d](solids.md#repair) [e](https://x.org/a.md) [f](#here) ![g](gallery/vase.png) "
        "[h](../engine/core/registry.py)"
    )
    # the README, as the home page: its links are relative to the repository's root
    home = hooks.rewrite_links(
        "[x](docs/solids.md) ![y](docs/gallery/lamp.png) [z](graphs/) [w](nodes/)",
        "index.md",
        site,
        base="",
    )
    assert home == "[x](solids.md) ![y](gallery/lamp.png) [z](gallery/index.md) " + (
        "[w](reference/index.md)"
    )
    # from a page one folder down
    down = hooks.rewrite_links("[a](../../graphs/vase.yaml)", "ref/a.md", site, base="docs/ref")
    assert down == "[a](../gallery/vase.md)"


# ------------------------------------------------------------------------------ gallery


def test_every_example_graph_has_a_picture_of_it_as_it_is_now():
    stale = gallery.stale(ROOT / "graphs", DOCS / "gallery")
    assert not stale, (
        f"no picture, or one of an older version, for {', '.join(stale)}: run "
        f"python -m formgraph.viewer.gallery {' '.join(stale)}  (and look at it)"
    )


def test_a_gallery_page_shows_the_picture_params_nodes_and_yaml():
    def link(t: str) -> str | None:
        return None if t.endswith(".yaml") else f"ref#{t}"

    page = hooks.gallery_page(ROOT / "graphs" / "lamp.yaml", link)
    assert page.startswith("# lamp\n")
    assert "![lamp](lamp.png)" in page
    assert "| `top` |" in page  # a param row
    assert "[`nurbs.loft`](ref#nurbs.loft)" in page
    assert "[`parts/ring.yaml`](../graphs/parts/ring.yaml) (a subgraph)" in page
    assert (ROOT / "graphs" / "lamp.yaml").read_text().strip() in page
    index = hooks.gallery_index(hooks.example_graphs())
    for p in hooks.example_graphs():
        assert f"]({p.stem}.md)" in index and f"({p.stem}.png)" in index


# ---------------------------------------------------------------------- node reference


def test_the_reference_has_a_page_per_family_with_every_node_and_port():
    families = catalogue.families()
    shipped = {s.family for s in SHIPPED.values()}
    assert shipped <= set(families)
    index = catalogue.index_markdown()
    for family in shipped:
        page = catalogue.family_markdown(family)
        assert page.startswith(f"# {family}\n")
        package = __import__(f"formgraph.nodes.{family}", fromlist=["_"])
        assert " ".join(package.__doc__.split()[:6]) in page  # the package says what it holds
        assert f"]({family}.md)" in index
        for spec in families[family]:
            assert f"### `{spec.name}` {{ #{spec.name} }}" in page
            assert f"]({family}.md#{spec.name})" in index
            entry = page.split(f"### `{spec.name}`")[1].split("\n### ")[0]
            for port in spec.inputs.values():
                assert f"| `{port.name}` |" in entry, (spec.name, port.name)
            assert "\nParameters\n" not in entry  # the table says it once


def test_a_node_entry_keeps_its_prose_its_defaults_and_its_example():
    entry = catalogue.node_markdown(SHIPPED["curves.grow"], 3)
    assert "differential growth" in entry and "O(n log n)" in entry
    assert "| `split` | float | 1 |" in entry
    assert '**Example:** ``grown: {type: curves.grow, simulate: {state: curve, from: "@seed"' in (
        entry
    )
    assert "**Output:** NurbsCurve." in entry
    multi = catalogue.node_markdown(SHIPPED["mesh.measure"], 3)
    assert "**Outputs:** `area` (float)" in multi


def test_a_page_the_nav_does_not_list_is_shown_all_the_same():
    nav = [{"Home": "index.md"}, {"Node reference": hooks.REFERENCE}]
    config = SimpleNamespace(nav=nav)
    hooks.on_config(config)
    listed = hooks._nav_files(config.nav)
    assert "reference/mesh.md" in listed  # a page per family
    more = next(s for s in config.nav if isinstance(s, dict) and hooks.MORE in s)[hooks.MORE]
    assert "solids.md" in more and "speed-table.md" not in more
