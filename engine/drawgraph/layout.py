"""A picture of a graph itself: a layered drawing of its DAG, as SVG (our own code) or PNG.

Each node is a box with its name, its type, one row per wired input port and its output
type(s); each param is a box of its own, wired (dashed) to the ports whose expressions read
it; each wire is labelled with the type that flows through it. After an evaluation the
boxes are coloured computed or cached and show their seconds: a profile at a glance.

Layout (Sugiyama's layered scheme): the layers are the graph's topological generations
(networkx), so sources sit left and sinks right, with sources (params included) pulled
right next to their first reader; a wire that spans several layers gets a bend point in
each layer it crosses; the order within each layer is improved by a few barycenter sweeps
(Sugiyama, Tagawa and Toda, "Methods for visual understanding of hierarchical system
structures", IEEE SMC 1981) to cut crossings.

Marks on a node ("export", "subgraph", "repeat i", ...) come from the functions in
:data:`MARKS`, each ``(graph, node) -> list[str]``; append one to mark nodes of a new kind.
A marked "repeat" node is drawn as a stack of boxes, a subgraph with a double border.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..core.errors import FormgraphError
from ..core.registry import node_types
from ..language.model import Expr, Items, Literal, exprs_of, parse_input, wires_of
from .drawing import Drawing
from .shapes import Circle, Rect, Text, Wire, text_width

__all__ = ["MARKS", "draw_graph", "failed_nodes", "node_marks"]

Mark = Callable[[Any, str], list[str]]

FAMILY_COLORS = {
    "points": "#9467bd",
    "curves": "#2ca02c",
    "nurbs": "#1f77b4",
    "surfaces": "#17becf",
    "mesh": "#ff7f0e",
    "geometry": "#e377c2",
    "offset": "#bcbd22",
    "export": "#7f7f7f",
}
STATUS_FILL = {
    "computed": "#fde2c4",
    "cached": "#d9e9f7",
    "failed": "#f4b6b6",
    "not run": "#f1f1f1",
    None: "white",
}
PARAM_FILL, PARAM_STROKE = "#fff6d5", "#b39a3e"
INK, GREY, WIRE = "#222222", "#666666", "#7a7a7a"

PAD, ROW, HEAD, MIN_W = 9.0, 16.0, 20.0, 120.0
V_GAP, MIN_H_GAP, MARGIN, TOP = 16.0, 56.0, 16.0, 58.0


# ------------------------------------------------------------------------------- marks


def _registry(graph: Any) -> dict[str, Any]:
    """The node types ``graph`` can use (subgraph files too, where the graph knows them)."""
    types = getattr(graph, "node_types", None)
    if callable(types):
        try:
            return types()
        except FormgraphError:  # a subgraph file that does not load: draw without it
            pass
    return node_types()


def _type_of(graph: Any, name: str) -> str:
    """A node's type, without building ``graph.nodes`` (a new dict on every call)."""
    return graph._nodes[name].type


def _export_mark(graph: Any, name: str) -> list[str]:
    spec = _registry(graph).get(_type_of(graph, name))
    return ["export"] if spec is not None and spec.is_export else []


def _subgraph_mark(graph: Any, name: str) -> list[str]:
    return ["subgraph"] if _type_of(graph, name).endswith((".yaml", ".yml")) else []


def _repeat_mark(graph: Any, name: str) -> list[str]:
    loops = _repeat_of(graph, name)
    return [f"repeat {', '.join(loops)}".strip()] if loops is not None else []


def _simulate_mark(graph: Any, name: str) -> list[str]:
    sim = getattr(graph._nodes[name], "simulate", None)
    return [f"simulate {sim.state}"] if sim is not None else []


MARKS: list[Mark] = [_export_mark, _subgraph_mark, _repeat_mark, _simulate_mark]

#: marks drawn as a stack of boxes: one box per item (a repeat) or per step (a simulation)
STACKED = ("repeat", "simulate")


def node_marks(graph: Any, name: str, marks: Iterable[Mark] | None = None) -> list[str]:
    """The marks of node ``name`` from every function in ``marks`` (default :data:`MARKS`)."""
    out: list[str] = []
    for mark in MARKS if marks is None else marks:
        out.extend(m for m in mark(graph, name) if m not in out)
    return out


def _repeat_of(graph: Any, name: str) -> dict[str, Any] | None:
    """A node's ``repeat:`` as {loop name: its source (an input)}, or None without one."""
    repeat = getattr(graph._nodes[name], "repeat", None)
    if not repeat:
        return None
    if hasattr(repeat, "name") and hasattr(repeat, "source"):  # model.Repeat
        return {repeat.name: repeat.source}
    if isinstance(repeat, Mapping):
        out = {}
        for loop, raw in repeat.items():
            try:
                out[str(loop)] = parse_input(raw)
            except FormgraphError:
                continue
        return out
    return {}


# ------------------------------------------------------------------------------ model


@dataclass
class Box:
    key: str  # "n:name" or "p:name"
    title: str
    subtitle: str
    ports: list[str] = field(default_factory=list)  # wired input ports, top to bottom
    outputs: list[tuple[str, str]] = field(default_factory=list)  # (output, type name)
    marks: list[str] = field(default_factory=list)
    status: str | None = None
    status_text: str = ""
    family: str = ""
    x: float = 0.0
    y: float = 0.0

    @property
    def is_param(self) -> bool:
        return self.key.startswith("p:")

    @property
    def width(self) -> float:
        texts = [text_width(self.title, 13, True), text_width(self.subtitle, 11)]
        texts += [text_width(p, 11) + 8 for p in self.ports]
        texts += [text_width(self.out_text(o, t), 11) + 8 for o, t in self.outputs]
        texts += [text_width(self.status_text, 10)]
        return max(MIN_W, max(texts) + 2 * PAD)

    @property
    def height(self) -> float:
        rows = len(self.ports) + len(self.outputs) + (1 if self.status_text else 0)
        return HEAD + ROW + rows * ROW + PAD

    def out_text(self, output: str, type_name: str) -> str:
        return f"{output}: {type_name}" if output else f"-> {type_name}"

    def port_y(self, port: str) -> float:
        return self.y + HEAD + ROW + (self.ports.index(port) + 0.5) * ROW + 4

    def output_y(self, output: str) -> float:
        if self.is_param:
            return self.y + self.height / 2
        names = [o for o, _ in self.outputs]
        i = names.index(output) if output in names else 0
        return self.y + HEAD + ROW + (len(self.ports) + i + 0.5) * ROW + 4


@dataclass(frozen=True)
class Edge:
    src: str
    output: str  # the source's output ("" for the only one)
    dst: str
    port: str
    label: str
    param: bool = False


def _output_types(graph: Any, registry: dict[str, Any]) -> dict[tuple[str, str | None], Any]:
    """The checker's type of each node output (a repeated transform of a mesh carries
    ``list[Mesh]``, not its port's ``Geometry | list[Geometry]``); empty for a graph that
    has no outline to ask."""
    from ..language.check import output_types

    outline = getattr(graph, "_outline", None)
    if not callable(outline):
        return {}
    try:
        return output_types(outline(), registry)
    except FormgraphError:  # a subgraph file that does not load: the ports' own types
        return {}


def _type_name(pt: Any) -> str:
    return getattr(pt, "name", str(pt))


def _param_names(value: Any, port_type: Any, params: set[str]) -> list[str]:
    """The params that an input's expressions (or expression-typed text) read."""
    from ..language.expr import compile_expression

    names: set[str] = set()
    for e in exprs_of(value):
        names |= set(e.compiled.names)
    if isinstance(value, Expr):
        names |= set(value.compiled.names)
    texts = [value.value] if isinstance(value, Literal) else []
    if isinstance(value, Items):
        texts = [i.value for i in value.items if isinstance(i, Literal)]
    if port_type is not None and getattr(port_type, "is_expression", False):
        for text in texts:
            if isinstance(text, str):
                try:
                    names |= set(compile_expression(text).names)
                except FormgraphError:
                    pass
    return [n for n in sorted(names) if n in params]


def _model(graph: Any, marks: Iterable[Mark] | None) -> tuple[dict[str, Box], list[Edge]]:
    registry = _registry(graph)
    params = graph.param_defs
    values = graph.params
    boxes: dict[str, Box] = {}
    for name, p in params.items():
        if p.type_name and p.default is None:  # a slot filled from Python (`type: int` is not)
            sub = f"{p.type_name} input"
        else:
            sub = f"= {_short(values.get(name))}"
            if p.min is not None or p.max is not None:
                lo = "" if p.min is None else f"{p.min:g}"
                hi = "" if p.max is None else f"{p.max:g}"
                sub += f" [{lo}..{hi}]"
        boxes[f"p:{name}"] = Box(f"p:{name}", name, sub, family="param")
    edges: list[Edge] = []
    types = graph.nodes
    known = _output_types(graph, registry)
    for name, type_name in types.items():
        spec = registry.get(type_name)
        nd = graph._nodes[name]
        box = Box(f"n:{name}", name, type_name, family=type_name.split(".", 1)[0])
        box.marks = node_marks(graph, name, marks)
        repeated = any(m.startswith("repeat") for m in box.marks)
        if spec is not None:
            for out, pt in spec.outputs.items():
                found = known.get((name, out if spec.multi_output else None))
                label = _type_name(pt)
                label = f"list[{label}]" if repeated else label
                label = found.name if found is not None else label
                box.outputs.append(("" if not spec.multi_output else out, label))
        else:
            box.outputs.append(("", "outputs"))
        if getattr(nd, "simulate", None) is not None and box.outputs:  # every step's output
            box.outputs.append(("frames", f"list[{box.outputs[0][1]}]"))
        inputs = dict(nd.inputs)
        for loop, source in (_repeat_of(graph, name) or {}).items():
            inputs[f"repeat {loop}"] = source
        sim = getattr(nd, "simulate", None)
        if sim is not None:  # the state comes from 'from' (step 0), then from itself
            inputs.pop(sim.state, None)
            inputs[f"{sim.state} from"] = sim.source
            inputs["steps" if "steps" not in inputs else "simulate steps"] = sim.steps
        for port, value in inputs.items():
            port_type = spec.inputs[port].type if spec is not None and port in spec.inputs else None
            used = False
            for w in wires_of(value):
                if w.node not in types:
                    continue
                edges.append(Edge(f"n:{w.node}", w.output or "", f"n:{name}", port, ""))
                used = True
            for p in _param_names(value, port_type, set(params)):
                edges.append(Edge(f"p:{p}", "", f"n:{name}", port, "", param=True))
                used = True
            if used:
                box.ports.append(port)
        boxes[box.key] = box
    # label each wire with the type that leaves its source
    labelled = []
    for e in edges:
        src = boxes[e.src]
        if e.param:
            p = params[e.src[2:]]
            label = p.type_name or type(values.get(e.src[2:])).__name__
        else:
            outs = dict(src.outputs)
            label = outs.get(e.output) or (src.outputs[0][1] if src.outputs else "")
            if e.output and e.output not in outs:
                label = e.output
        labelled.append(Edge(e.src, e.output, e.dst, e.port, label, e.param))
    return boxes, labelled


def _short(value: Any) -> str:
    text = repr(value) if not isinstance(value, str) else value
    return text if len(text) <= 24 else text[:21] + "..."


# ----------------------------------------------------------------------------- layout


def _layers(boxes: dict[str, Box], edges: list[Edge]) -> dict[str, int]:
    """Each box's layer: its topological generation, sources pulled right to one layer
    before their first reader."""
    import networkx as nx

    g = nx.DiGraph()
    g.add_nodes_from(boxes)
    g.add_edges_from((e.src, e.dst) for e in edges)
    layer = {}
    for i, generation in enumerate(nx.topological_generations(g)):
        for key in generation:
            layer[key] = i
    for key in reversed(list(nx.topological_sort(g))):
        succ = list(g.successors(key))
        if succ and g.in_degree(key) == 0:
            layer[key] = max(layer[key], min(layer[s] for s in succ) - 1)
    return layer


def _order(
    keys_by_layer: list[list[str]],
    links: list[tuple[str, str, float, float]],
    sweeps: int = 4,
) -> list[list[str]]:
    """Reorder each layer by the barycenter of its neighbours in the layer before (down
    sweeps) or after (up sweeps). A link ``(a, b, at_a, at_b)`` meets its ends at
    ``at_a`` / ``at_b`` (0 to 1) down a box: the row of a port, so that two wires into one
    node arrive in the order of its ports instead of crossing."""
    preds: dict[str, list[tuple[str, float]]] = {}
    succs: dict[str, list[tuple[str, float]]] = {}
    for a, b, at_a, at_b in links:
        succs.setdefault(a, []).append((b, at_b))
        preds.setdefault(b, []).append((a, at_a))
    order = [list(layer) for layer in keys_by_layer]
    for sweep in range(sweeps):
        down = sweep % 2 == 0
        rng = range(1, len(order)) if down else range(len(order) - 2, -1, -1)
        for i in rng:
            ref = order[i - 1] if down else order[i + 1]
            pos = {k: j for j, k in enumerate(ref)}
            near = preds if down else succs

            def bary(item: tuple[int, str], pos: dict[str, int] = pos, near: Any = near) -> float:
                j, key = item
                ns = [pos[n] + at for n, at in near.get(key, []) if n in pos]
                return sum(ns) / len(ns) if ns else float(j) + 0.5

            order[i] = [k for _, k in sorted(enumerate(order[i]), key=bary)]
    return order


def draw_graph(
    graph: Any,
    path: str | os.PathLike[str] | None = None,
    *,
    stats: Mapping[str, Any] | None = None,
    marks: Iterable[Mark] | None = None,
    failed: Iterable[str] = (),
) -> Drawing:
    """Draw ``graph``'s nodes, params and wires as a layered diagram.

    Parameters
    ----------
    graph : Graph
        The graph (it is not evaluated here).
    path : str or path, optional
        Also write the drawing there, as ``.svg`` or ``.png``.
    stats : mapping, optional
        Node -> stat (``status``, ``seconds``) to colour by; default ``graph.stats``, the
        record of its last evaluation (empty before one: no colours).
    marks : iterable of callables, optional
        Mark functions ``(graph, node) -> list[str]``; default :data:`MARKS`.
    failed : iterable of str
        Nodes whose run failed (drawn red): see :func:`failed_nodes`.

    Returns
    -------
    Drawing
        ``.svg`` is the SVG text, ``.save(path)`` writes SVG or PNG, ``.png()`` gives PNG
        bytes; Jupyter shows it inline.

    Example
    -------
    >>> import formgraph as fg
    >>> g = fg.Graph()
    >>> g.add("pts", "points.circle", count=8)
    >>> g.add("c", "curves.polyline", points="@pts", closed=True)
    >>> "<svg" in fg.draw_graph(g).svg
    True
    """
    stats = graph.stats if stats is None else stats
    failed = set(failed)
    boxes, edges = _model(graph, marks)
    ran = bool(stats) or bool(failed)
    for key, box in boxes.items():
        if box.is_param:
            continue
        st = stats.get(key[2:]) if ran else None
        if key[2:] in failed:
            box.status, box.status_text = "failed", "failed"
        elif st is not None:
            box.status = st.status
            where = f" ({st.source})" if getattr(st, "source", "") in ("disk",) else ""
            if getattr(st, "items", None) is not None:  # a repeat's items, a simulation's steps
                where += f" {st.computed_items}/{st.items} {getattr(st, 'unit', 'items')}"
            box.status_text = f"{st.status}{where} {_seconds(st.seconds)}"
        elif ran:
            box.status = "not run"
    layer = _layers(boxes, edges)
    n_layers = max(layer.values(), default=-1) + 1
    # a bend point in every layer a wire crosses
    members: list[list[str]] = [[] for _ in range(n_layers)]
    for key in boxes:  # author order: params, then nodes
        members[layer[key]].append(key)
    links: list[tuple[str, str, float, float]] = []
    chains: list[list[str]] = []
    for i, e in enumerate(edges):
        chain = [e.src]
        for lay in range(layer[e.src] + 1, layer[e.dst]):
            dummy = f"d:{i}:{lay}"
            members[lay].append(dummy)
            chain.append(dummy)
        chain.append(e.dst)
        src, dst = boxes[e.src], boxes[e.dst]
        at_src = (src.output_y(e.output) - src.y) / src.height
        at_dst = (dst.port_y(e.port) - dst.y) / dst.height
        ats = [at_src] + [0.5] * (len(chain) - 2) + [at_dst]
        for a, b, at_a, at_b in zip(chain[:-1], chain[1:], ats[:-1], ats[1:], strict=True):
            links.append((a, b, at_a, at_b))
        chains.append(chain)
    order = _order(members, links)
    return _place_and_draw(graph, boxes, edges, chains, order, ran, path)


def failed_nodes(error: BaseException) -> list[str]:
    """The nodes an evaluation error names (a NodeError's node, a GraphError's problems)."""
    where = getattr(error, "where", None)
    if where is not None and getattr(where, "node", None):
        return [where.node]
    problems = getattr(error, "problems", [])
    return list(dict.fromkeys(p.where.node for p in problems if p.where.node))


def _seconds(s: float) -> str:
    return f"{s * 1000:.3g} ms" if s < 1 else f"{s:.3g} s"


def _place_and_draw(
    graph: Any,
    boxes: dict[str, Box],
    edges: list[Edge],
    chains: list[list[str]],
    order: list[list[str]],
    ran: bool,
    path: str | os.PathLike[str] | None,
) -> Drawing:
    def height(key: str) -> float:
        return boxes[key].height if key in boxes else 10.0

    widths = [max([boxes[k].width for k in lay if k in boxes], default=20.0) for lay in order]
    # room left of each layer for the labels of the wires that arrive there
    arriving = [0.0] * len(order)
    index = {k: i for i, lay in enumerate(order) for k in lay}
    for e in edges:
        arriving[index[e.dst]] = max(arriving[index[e.dst]], text_width(e.label, 10) + 26)
    xs, x = [], MARGIN
    for i, w in enumerate(widths):
        x += 0.0 if i == 0 else max(MIN_H_GAP, arriving[i])
        xs.append(x)
        x += w
    header = text_width(_title(graph), 15, True) + (text_width(_summary(graph), 11) + 40) * ran
    page_w = max(x + MARGIN, header + 2 * MARGIN, 300.0)
    column_h = [sum(height(k) for k in lay) + V_GAP * (len(lay) - 1) for lay in order]
    tallest = max(column_h, default=0.0)
    point: dict[str, float] = {}  # the y of each bend point
    for i, lay in enumerate(order):
        y = TOP + (tallest - column_h[i]) / 2
        for k in lay:
            if k in boxes:
                boxes[k].x, boxes[k].y = xs[i], y
            else:
                point[k] = y + 5.0
            y += height(k) + V_GAP
    d = Drawing(page_w, TOP + tallest + MARGIN + 4, title=_title(graph))
    _header(d, graph, ran, list(boxes.values()))
    layer_of = {k: i for i, lay in enumerate(order) for k in lay}
    labels: dict[tuple[str, str], set[str]] = {}
    for e, chain in zip(edges, chains, strict=True):
        src, dst = boxes[e.src], boxes[e.dst]
        pts = [(src.x + src.width, src.output_y(e.output))]
        for k in chain[1:-1]:  # straight across each crossed layer, in its own slot
            i = layer_of[k]
            pts += [(xs[i], point[k]), (xs[i] + widths[i], point[k])]
        pts.append((dst.x, dst.port_y(e.port)))
        data = (("from", e.src[2:]), ("to", f"{e.dst[2:]}.{e.port}"))
        if e.param:
            d.add(Wire(tuple(pts), "#b9a25a", 1.2, "param-wire", (4.0, 3.0), data))
        else:
            d.add(Wire(tuple(pts), WIRE, 1.5, "wire", None, data))
        labels.setdefault((e.dst, e.port), set()).add(e.label)
    for box in boxes.values():
        _box(d, box)
    for (dst, port), names in labels.items():
        box = boxes[dst]
        text = ", ".join(sorted(names))
        d.add(
            Text(
                box.x - 6,
                box.port_y(port) - 4,
                text,
                10,
                GREY,
                anchor="end",
                cls="wire-label",
                halo=True,
            )
        )
    if path is not None:
        d.save(path)
    return d


def _summary(graph: Any) -> str:
    stats = graph.stats
    total = sum(s.seconds for s in stats.values())
    computed = sum(1 for s in stats.values() if s.status == "computed")
    return f"last run: {computed} computed, {len(stats) - computed} cached, {_seconds(total)}"


def _title(graph: Any) -> str:
    name = os.path.basename(graph.file) if getattr(graph, "file", None) else "graph"
    return f"{name}: {len(graph.nodes)} nodes, {len(graph.params)} params"


def _header(d: Drawing, graph: Any, ran: bool, d_boxes: Iterable[Box] = ()) -> None:
    d.add(Text(MARGIN, 24, _title(graph), 15, INK, bold=True, cls="title"))
    legend_left = d.width - MARGIN
    if ran:
        summary = _summary(graph)
        x = d.width - MARGIN
        d.add(Text(x, 24, summary, 11, INK, anchor="end", cls="run"))
        labels = ["not run", "cached", "computed"]
        if any(b.status == "failed" for b in d_boxes):
            labels.insert(0, "failed")
        for label in labels:
            x -= text_width(label, 10) + 4
            d.add(Text(x, 42, label, 10, GREY, cls="legend"))
            x -= 16
            d.add(Rect(x, 33, 12, 11, STATUS_FILL[label], "#999999", 0.8, 2.0, cls="swatch"))
            x -= 10
        legend_left = x - 10
    desc = " ".join((getattr(graph, "description", "") or "").split())
    room = legend_left - MARGIN
    if desc and text_width(desc, 11) > room:
        while desc and text_width(desc + "...", 11) > room:
            desc = desc[:-1]
        desc = desc.rstrip() + "..." if desc else ""
    if desc:
        d.add(Text(MARGIN, 42, desc, 11, GREY, cls="description"))


def _box(d: Drawing, box: Box) -> None:
    w, h = box.width, box.height
    if box.is_param:
        d.add(Rect(box.x, box.y, w, h, PARAM_FILL, PARAM_STROKE, 1.2, 9.0, cls="param"))
    else:
        if any(m.startswith(STACKED) for m in box.marks):  # a stack: one box per item
            for off in (6.0, 3.0):
                d.add(Rect(box.x + off, box.y - off, w, h, "white", "#888888", 1.0, 5.0, "stack"))
        fill = STATUS_FILL[box.status]
        tip = f"{box.title} ({box.subtitle})"
        d.add(Rect(box.x, box.y, w, h, fill, "#4a4a4a", 1.2, 5.0, cls="node", title=tip))
        if "subgraph" in box.marks:
            d.add(Rect(box.x + 3, box.y + 3, w - 6, h - 6, "none", "#4a4a4a", 0.8, 3.0, "inner"))
        color = FAMILY_COLORS.get(box.family, "#555555")
        d.add(Rect(box.x + 1, box.y + 1, 5, h - 2, color, "none", 0.0, 2.0, cls="family"))
        if "export" in box.marks:
            d.add(Rect(box.x, box.y, w, h, "none", "#4a4a4a", 1.2, 5.0, "export", (3.0, 2.0)))
    x = box.x + PAD
    d.add(Text(x, box.y + HEAD - 3, box.title, 13, INK, bold=True, cls="name"))
    d.add(Text(x, box.y + HEAD + ROW - 5, box.subtitle, 11, GREY, cls="type"))
    for port in box.ports:
        y = box.port_y(port)
        d.add(Circle(box.x, y, 3.0, WIRE, cls="port"))
        d.add(Text(x, y + 4, port, 11, INK, cls="port-name"))
    for output, type_name in box.outputs:
        y = box.output_y(output)
        d.add(Circle(box.x + w, y, 3.0, WIRE if not box.is_param else PARAM_STROKE, cls="output"))
        d.add(
            Text(
                box.x + w - PAD,
                y + 4,
                box.out_text(output, type_name),
                11,
                INK,
                anchor="end",
                cls="output-type",
            )
        )
    if box.is_param:
        d.add(Circle(box.x + w, box.y + h / 2, 3.0, PARAM_STROKE, cls="output"))
    if box.status_text:
        y = box.y + h - PAD + 1
        d.add(Text(x, y, box.status_text, 10, "#444444", cls="status"))
    if box.marks:
        text = "  ".join(box.marks)
        tw = text_width(text, 9) + 10
        d.add(Rect(box.x + w - tw - 4, box.y - 8, tw, 14, "#444444", "none", 0.0, 7.0, "mark"))
        d.add(Text(box.x + w - 9, box.y + 2.5, text, 9, "white", anchor="end", cls="mark-text"))
