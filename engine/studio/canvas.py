"""The studio's canvas: the graph's drawing as a node editor, and the spreadsheet.

The browser half (``canvas.js``, shipped in the package and loaded with the page) turns
gestures into requests; this half answers each with an edit of the YAML text the page sent
(:mod:`.textedit`), checked, which the page applies through the editor. A wire the checker
refuses is not written: its sentence goes back, to be shown at the port.

- :func:`palette`: the node types to add, with their first doc line and ports;
- :func:`canvas_svg`: the drawing with hit targets (node boxes, input and output ports);
- :class:`Canvas`: the requests, run in the studio's worker, and their replies;
- :func:`sheet`: a page of the shown value's elements and attributes (rows by columns).

Where the canvas draws nodes: the file's ``layout:`` positions first, then those of the
last drawing, so a node laid out once stays put while others come and go.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from formgraph.core.errors import GraphError
from formgraph.language.incremental import node_span

from . import textedit

__all__ = ["ROWS", "Canvas", "canvas_svg", "palette", "sheet"]

ROWS = 50  # rows of the spreadsheet a page
JS = Path(__file__).with_name("canvas.js")


def palette(types: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Each node type as the palette lists it: name, first doc line, inputs, outputs."""
    out = []
    for name, spec in sorted(types.items()):
        if name.endswith((".yaml", ".yml")):
            continue
        inputs = [
            {"name": p, "type": port.type.name, "required": port.required}
            for p, port in spec.inputs.items()
        ]
        outputs = [
            {"name": o if spec.multi_output else "", "type": t.name}
            for o, t in spec.outputs.items()
        ]
        summary = spec.summary.replace("``", "")  # (numpydoc's literals, read as plain text)
        out.append({"name": name, "summary": summary, "inputs": inputs, "outputs": outputs})
    return out


def canvas_svg(drawing: Any, subgraphs: frozenset[str] = frozenset()) -> str:
    """The drawing's SVG with invisible hit targets on top: a rectangle per box
    (``data-node``; ``data-subgraph`` for a subgraph node) and a circle per input port
    (``data-in``, ``data-port``) and output (``data-out``, ``data-output``)."""
    boxes = drawing.meta.get("boxes", {})
    hits = []
    for shape in drawing.shapes:  # a wide invisible stroke over each wire, to click
        data = dict(getattr(shape, "data", ()) or ())
        if "from" in data and hasattr(shape, "path_data"):
            hits.append(
                f'<path d="{shape.path_data()}" class="fg-wire-hit" '
                f"data-from={quoteattr(data['from'])} data-to={quoteattr(data['to'])}/>"
            )
    for name, b in boxes.items():
        q = quoteattr(name)
        sub = ' data-subgraph="1"' if name in subgraphs else ""
        param = ' data-param="1"' if b["param"] else ""
        hits.append(
            f'<rect data-node={q}{sub}{param} x="{b["x"]:.1f}" y="{b["y"]:.1f}" '
            f'width="{b["w"]:.1f}" height="{b["h"]:.1f}" class="fg-hit"/>'
        )
    for name, b in boxes.items():
        q = quoteattr(name)
        for port, y in b["ports"].items():
            hits.append(
                f'<circle data-in={q} data-port={quoteattr(port)} cx="{b["x"]:.1f}" '
                f'cy="{y:.1f}" r="7" class="fg-port"/>'
            )
        for output, y in b["outputs"].items():
            hits.append(
                f"<circle data-out={q} data-output={quoteattr(output)} "
                f'cx="{b["x"] + b["w"]:.1f}" cy="{y:.1f}" r="7" class="fg-port"/>'
            )
    svg = drawing.svg
    svg = svg[svg.index("<svg") :]  # no XML declaration inside a page
    return svg.replace("</svg>", "".join(hits) + "</svg>")


MAX_XY = 1e6  # a position further out is the page's bug or a hostile request


def _xy(x: Any, y: Any) -> tuple[float, float]:
    """A box's position from a request: two finite numbers, put within the page."""
    p = (float(x), float(y))
    if not all(math.isfinite(c) for c in p):
        raise textedit.EditError("a position is two finite numbers")
    return (min(max(p[0], 0.0), MAX_XY), min(max(p[1], 0.0), MAX_XY))


class Canvas:
    """The canvas's requests of one studio page, answered in its worker thread.

    Parameters
    ----------
    page : Page
        The studio page (its session, worker, state and loop).
    bind : bool
        Register the requests with the page's trame controller and state (False: only the
        session is used, as the tests drive it).
    """

    def __init__(self, page: Any, *, bind: bool = True):
        self.page = page
        self.placed: dict[str, tuple[float, float]] = {}  # the last drawing's boxes
        # texts checked lately -> (their graph, its problems): a gesture checks the text
        # before and after it, and the next gesture's "before" is this one's "after"
        self._checked: dict[str, tuple[Any, list[Any]]] = {}
        # an accepted edit's text and its graph, checked: the session cooks it as it is
        # rather than reading and checking the text again
        self._handover: tuple[str, Any] | None = None
        self._kinds = itertools.count()
        if bind:  # (``bind=False``: the requests' half alone, for a page without trame)
            self._bind(page)

    def _bind(self, page: Any) -> None:
        ctrl = page.ctrl
        for op in ("wire", "unwire", "add", "delete", "rename", "move"):
            ctrl.trigger(f"canvas_{op}")(self._asker(op))
        ctrl.trigger("sheet")(self._sheet)
        ctrl.trigger("open_subgraph")(self._open_subgraph)
        s = page.state
        s.canvas_reply = None
        s.sheet_open = False
        s.sheet = None
        s.subgraph_view = None
        s.palette = []

    # ------------------------------------------------------------------- drawing

    def positions(self, graph: Any) -> dict[str, tuple[float, float]]:
        """Where to draw ``graph``'s boxes: the file's ``layout:``, else the last drawing's."""
        names = set(graph._nodes) | set(graph.param_defs)
        out = {n: p for n, p in self.placed.items() if n in names}
        out.update(getattr(graph, "layout", {}) or {})
        return out

    def drawn(self, drawing: Any) -> None:
        """Remember where a drawing put each box (in the worker, which draws)."""
        self.placed = {n: (b["x"], b["y"]) for n, b in drawing.meta.get("boxes", {}).items()}

    # ------------------------------------------------------------------ requests

    def _asker(self, op: str) -> Any:
        def ask(rid: Any = None, *args: Any) -> None:
            if not args or not isinstance(args[-1], str):
                return  # not our page's request: nothing to answer
            *rest, text = args
            kind = f"canvas-{next(self._kinds)}"  # each its own: none supersedes another
            self.page.worker.submit(kind, self.answer, rid, op, rest, text)

        return ask

    def answer(self, rid: Any, op: str, args: list[Any], text: str) -> dict[str, Any]:
        """In the worker: the reply to request ``rid`` (``op`` with ``args`` on ``text``)."""
        try:
            edits, port = self._edits(op, args, text)
        except textedit.EditError as exc:
            return {"id": rid, "refused": str(exc)}
        except (TypeError, ValueError) as exc:  # a malformed request (not from our page)
            return {"id": rid, "refused": f"not understood: {exc}"}
        new = textedit.apply(text, edits)
        if port is not None:
            self._check(new, edited=(text, port[0]))  # (one node's lines changed)
            fresh = [
                m for m in self._problems_at(new, *port) if m not in self._problems_at(text, *port)
            ]
            if fresh:
                return {"id": rid, "refused": fresh[0], "port": list(port)}
            graph, problems = self._check(new)
            ok = not problems and graph is not self.page.session.graph
            self._handover = (new, graph) if ok else None
        return {
            "id": rid,
            "edits": [e.where(text) for e in textedit.merged(edits)],
            "text": new,
        }

    def _edits(
        self, op: str, args: list[Any], text: str
    ) -> tuple[list[textedit.Edit], tuple[str, str] | None]:
        from formgraph.language.yamlio import parse

        if op == "wire":  # (read once for the edit and the checks around it)
            read = self._check(text)[0]
            params, nodes = read._params, read._nodes
        else:
            doc = parse(text, str(self.page.session.path))
            params, nodes = doc.params, doc.nodes
        types = self._types()
        if op == "wire":
            src, output, dst, port = (str(a) for a in args)
            if src == dst:
                raise textedit.EditError("a node cannot take its own output")
            ref = f"={src}" if src in params else None
            listed = False
            nd = nodes.get(dst)
            spec = types.get(nd.type) if nd is not None else None
            if ref is None and spec is not None and port in spec.inputs:
                kinds = spec.inputs[port].type.kinds
                src_nd = nodes.get(src)
                src_spec = types.get(src_nd.type) if src_nd is not None else None
                out_type = None
                if src_spec is not None:
                    out_type = src_spec.outputs.get(output) or next(
                        iter(src_spec.outputs.values()), None
                    )
                src_list = out_type is not None and all(k.is_list for k in out_type.kinds)
                listed = any(k.is_list for k in kinds) and not src_list
                if src_spec is not None and not src_spec.multi_output:
                    output = ""
            within = node_span(text, nodes, dst)  # (dst's lines: all the edit composes)
            edits = textedit.wire(
                text, src, output, dst, port, listed=listed, ref=ref, within=within
            )
            return edits, (dst, port)
        if op == "unwire":
            src, to = (str(a) for a in args)
            dst, _, port = to.partition(".")
            if src in params:
                raise textedit.EditError(
                    f"'{dst}.{port}' reads the param '{src}' in its expression: edit it in the text"
                )
            return textedit.unwire(text, src, "", dst, port), None
        if op == "add":
            type_name, (x, y) = str(args[0]), _xy(args[1], args[2])
            spec = types.get(type_name)
            if spec is None:
                raise textedit.EditError(f"there is no node type '{type_name}'")
            base = re.sub(r"\W", "_", type_name.rsplit(".", 1)[-1]).strip("_") or "node"
            base = base if not base[0].isdigit() else f"n{base}"
            taken = set(nodes) | set(params)
            name = next(
                f"{base}{i or ''}" for i in itertools.count() if f"{base}{i or ''}" not in taken
            )
            required = [p for p, port in spec.inputs.items() if port.required]
            return textedit.add_node(text, name, type_name, required, (x, y)), None
        if op == "delete":
            return textedit.delete_node(text, str(args[0])), None
        if op == "rename":
            old, new = str(args[0]), str(args[1])
            edits = textedit.rename_node(text, old, new)
            if old in self.placed:  # the box stays where it was
                self.placed[new] = self.placed[old]
            return edits, None
        if op == "move":
            name, (x, y) = str(args[0]), _xy(args[1], args[2])
            if name not in nodes and name not in params:
                raise textedit.EditError(f"there is no node '{name}'")
            self.placed[name] = (x, y)
            return textedit.move_nodes(text, {name: (x, y)}), None
        raise ValueError(op)

    def _types(self) -> dict[str, Any]:
        from formgraph.core.registry import node_types

        graph = self.page.session.graph
        if graph is not None:
            try:
                return graph.node_types()
            except GraphError:
                pass
        return node_types()

    def _check(self, text: str, edited: tuple[str, str] | None = None) -> tuple[Any, list[Any]]:
        """``text`` as the session would open it (read, then checked) and its problems.

        The graph read is returned even when it does not check (its ``params`` and ``nodes``
        are what the gestures edit); the version the session shows is not read again.
        ``edited`` is (the text before, the node whose lines alone the edit changed): the
        graph of the text before, when it checked, is then read and checked again only
        where the edit reaches (:meth:`Graph.from_edit`, the same graph and problems).
        """
        from formgraph.evaluation.graph import Graph

        s = self.page.session
        if text == s.text and s.graph is not None and s.draft is s.graph:
            return s.graph, []
        if text in self._checked:
            return self._checked[text]
        how = dict(file=str(s.path), out_dir=s.out_dir, budget=s.budget, inputs_dir=s.inputs_dir)
        before = self._check(edited[0])[0] if edited is not None else None
        if before is not None:
            graph = Graph.from_edit(before, text, edited[1], check=False, **how)
        else:
            graph = Graph.from_text(text, check=False, **how)
        try:
            graph.check()
            problems: list[Any] = []
        except GraphError as exc:
            problems = list(exc.problems)
        while len(self._checked) >= 4:  # (this gesture's two texts, and the last one's)
            del self._checked[next(iter(self._checked))]
        self._checked[text] = (graph, problems)
        return graph, problems

    def _problems_at(self, text: str, node: str, port: str) -> list[str]:
        return [
            p.message
            for p in self._check(text)[1]
            if p.where.node == node and p.where.input in (port, None)
        ]

    def take_checked(self, text: str) -> Any:
        """The graph of an accepted edit's ``text``, checked and not yet cooked (else None):
        handed over once, to the session's next opening of that text."""
        handover, self._handover = self._handover, None
        if handover is None or handover[0] != text:
            return None
        self._checked.pop(text, None)  # (the session owns it now: it gains a cache)
        return handover[1]

    def reply(self, result: dict[str, Any]) -> None:
        """On the page's loop: the reply to the page; an accepted edit is cooked at once
        (the editor's echo of it is then not cooked again)."""
        page = self.page
        if "text" in result:
            page._editor_text = result["text"]
            new = result["text"]
            page.worker.submit("text", lambda: page.session.open(new, self.take_checked(new)))
        with page.state:
            page.state.canvas_reply = result
            if "refused" in result:
                page.state.status = f"{page.session.path.name}: {result['refused']}"
                page.state.status_bad = True

    # ----------------------------------------------------------------- spreadsheet

    def _sheet(self, domain: Any = "points", number: Any = 0) -> None:
        page = self.page
        page.state.sheet_open = True
        self.sheet_args = (str(domain), int(number) if str(number).isdigit() else 0)
        page.worker.submit("sheet", self.make_sheet)

    def make_sheet(self) -> dict[str, Any] | None:
        """In the worker: the spreadsheet of the shown value (its first geometry)."""
        domain, number = getattr(self, "sheet_args", ("points", 0))
        shown = self.page.session.last.shown
        return sheet(shown, domain, number)

    def _open_subgraph(self, name: Any) -> None:
        self.page.worker.submit("subgraph", self.read_subgraph, str(name))

    def read_subgraph(self, name: str) -> dict[str, Any] | None:
        """In the worker: a subgraph node's file, read only (one the graph already reads)."""
        graph = self.page.session.graph
        if graph is None or name not in graph._nodes:
            return None
        spec = self._types().get(graph._nodes[name].type)
        path = getattr(spec, "path", None)
        if path is None or Path(path) not in {Path(f) for f in graph.files}:
            return None
        from formgraph.core import safety
        from formgraph.language.yamlio import MAX_BYTES

        try:
            data = safety.read_regular(Path(path), max_bytes=MAX_BYTES)
        except OSError as exc:
            return {"name": name, "path": str(path), "text": f"cannot read it: {exc}"}
        return {"name": name, "path": str(path), "text": data.decode("utf-8", "replace")}


def sheet(shown: list[tuple[str, Any]], domain: str = "points", number: int = 0) -> dict | None:
    """A page of the first shown geometry's elements: ``domain`` ``"points"`` (``x y z``
    and the point attributes) or ``"faces"`` (the face attributes), :data:`ROWS` rows from
    page ``number``; a vector attribute spreads over one column per component."""
    from formgraph.viewer.datasets import geometry_items

    from .scene import INTERNAL

    for label, value in shown:
        items = [g for g in geometry_items(value) if hasattr(g, "to_pyvista")]
        if not items:
            continue
        data = items[0].to_pyvista()
        if domain == "faces":
            n, arrays, columns = data.n_cells, [], []
            source = data.cell_data
        else:
            n = data.n_points
            pts = np.asarray(data.points, dtype=float)
            arrays, columns = [pts[:, 0], pts[:, 1], pts[:, 2]], ["x", "y", "z"]
            source = data.point_data
        for name in source.keys():
            if name in INTERNAL or name.startswith(("vtk", "pyvista")):
                continue
            a = np.asarray(source[name])
            if a.ndim == 1:
                arrays.append(a)
                columns.append(name)
            elif a.ndim == 2:
                suffix = "xyz" if a.shape[1] == 3 else [f"[{i}]" for i in range(a.shape[1])]
                for i in range(a.shape[1]):
                    arrays.append(a[:, i])
                    columns.append(f"{name}.{suffix[i]}" if a.shape[1] == 3 else name + suffix[i])
        pages = max(1, -(-n // ROWS))
        number = min(max(number, 0), pages - 1)
        lo, hi = number * ROWS, min(n, (number + 1) * ROWS)
        cells = [[_cell(a[i]) for a in arrays] for i in range(lo, hi)]
        rows = [[i, *c] for i, c in zip(range(lo, hi), cells, strict=True)]
        return {
            "node": label,
            "domain": domain,
            "columns": ["#", *columns],
            "rows": rows,
            "page": number,
            "pages": pages,
            "total": n,
            "items": len(items),
        }
    return None


def _cell(v: Any) -> Any:
    if isinstance(v, (np.floating, float)):
        return float(f"{float(v):.6g}")
    if isinstance(v, (np.integer, int, np.bool_)):
        return v.item() if hasattr(v, "item") else v
    return str(v)
