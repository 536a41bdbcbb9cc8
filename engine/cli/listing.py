"""What ``formgraph nodes GRAPH.yaml`` and ``formgraph params GRAPH`` print: the node types
a graph uses (and its interface where it can be used as a node), and its params with their
types, defaults, ranges and the studio's slider steps."""

from __future__ import annotations

from typing import Any

from ..core.errors import GraphError
from ..language.params import param_kind, param_step

__all__ = ["nodes_text", "params_rows", "params_text"]


def nodes_text(g: Any) -> str:
    """The node types ``g`` uses, each with the nodes of that type; its interface as a node
    first when it has ``outputs:``, else a line saying how to make it one."""
    from ..language.catalogue import node_text

    by_type: dict[str, list[str]] = {}
    for name, type_name in g.nodes.items():
        nd = g._nodes[name]
        mark = f" (repeat {nd.repeat.name})" if nd.repeat is not None else ""
        by_type.setdefault(type_name, []).append(name + mark)
    count = len(g.nodes)
    head = (
        f"{g.file_label} uses {len(by_type)} node type{'s' if len(by_type) != 1 else ''} "
        f"in {count} node{'s' if count != 1 else ''}:"
    )
    width = max((len(t) for t in by_type), default=0)
    lines = [head] + [f"  {t:<{width}}  {', '.join(names)}" for t, names in sorted(by_type.items())]
    if g.outputs:
        try:
            interface = node_text(g.as_node_spec())
        except GraphError:
            interface = None
        if interface is not None:
            return f"As a node type:\n\n{interface}\n\n" + "\n".join(lines)
    else:
        lines.append(
            "It has no 'outputs:', so it is not a node type others can use (add outputs: "
            "{name: '@node'} to make it a part). Its params: formgraph params "
            f"{g.file_label}"
        )
    return "\n".join(lines)


def _type_name(p: Any) -> str:
    if p.choices is not None:
        return "choice"
    if p.type_name:
        return p.type_name
    kind = param_kind(p)
    if kind is not None:
        return {bool: "bool", str: "text", int: "int", float: "float"}[kind]
    return "list" if isinstance(p.default, list) else type(p.default).__name__


def params_rows(g: Any) -> list[dict[str, Any]]:
    """One row per param, in the file's order: ``name``, ``type``, ``default``, ``min``,
    ``max``, ``step`` (the studio slider's, for a number with both bounds), ``choices``,
    ``doc``, ``line`` (the values as the YAML wrote them)."""
    rows = []
    for name, p in g.param_defs.items():
        rows.append(
            {
                "name": name,
                "type": _type_name(p),
                "default": p.default,
                "min": p.min,
                "max": p.max,
                "step": param_step(p),
                "choices": None if p.choices is None else list(p.choices),
                "doc": p.doc,
                "line": p.line,
            }
        )
    return rows


def _text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else str(value)


def params_text(g: Any) -> str:
    """The params as a table: name, type, default, range (``min .. max`` or the choices),
    the slider's step and the doc."""
    rows = params_rows(g)
    if not rows:
        return f"{g.file_label} has no params"
    table = [("name", "type", "default", "range", "step", "doc")]
    for r in rows:
        if r["choices"] is not None:
            span = " | ".join(_text(c) for c in r["choices"])
        elif r["min"] is not None or r["max"] is not None:
            span = f"{_text(r['min']) or '-inf'} .. {_text(r['max']) or 'inf'}"
        else:
            span = ""
        table.append((r["name"], r["type"], _text(r["default"]), span, _text(r["step"]), r["doc"]))
    widths = [max(len(row[k]) for row in table) for k in range(5)]
    lines = [f"{g.file_label}: {len(rows)} param{'s' if len(rows) != 1 else ''}"]
    for row in table:
        cells = [f"{c:<{w}}" for c, w in zip(row[:5], widths, strict=True)] + [row[5]]
        lines.append("  " + "  ".join(cells).rstrip())
    return "\n".join(lines)
