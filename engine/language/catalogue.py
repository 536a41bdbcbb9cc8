"""Everything generated from the registry: the JSON Schema, the text catalogue and the docs.

``formgraph schema`` prints :func:`json_schema`; ``formgraph nodes`` prints
:func:`catalogue_text` / :func:`node_text`; ``docs/nodes.md`` is :func:`markdown` (a test
checks it is current; regenerate with ``formgraph nodes --markdown > docs/nodes.md``).
"""

from __future__ import annotations

import enum
import typing
from typing import Any

from ..core.registry import REQUIRED, NodeSpec, Port, node_types
from ..core.types import Faces, Kind, PortType, Vec3

WIRE = {
    "type": "string",
    "pattern": r"^@[A-Za-z_][\w-]*(\.[A-Za-z_]\w*)?$",
    "description": "a wire: '@node' or '@node.output'",
}
EXPR = {"type": "string", "pattern": "^=", "description": "an expression over the graph params"}
REPEAT = {
    "type": "object",
    "minProperties": 1,
    "maxProperties": 1,
    "additionalProperties": {
        "anyOf": [{"type": "integer", "minimum": 0}, EXPR, WIRE, {"type": "array"}]
    },
    "description": "run the node once per item: {name: count | list | '@list' | '@points'}",
}
SIMULATE = {
    "type": "object",
    "properties": {
        "state": {"type": "string", "description": "the input that takes the previous step"},
        "from": {"description": "step 0: a wire, an expression or a literal"},
        "steps": {"anyOf": [{"type": "integer", "minimum": 0}, EXPR]},
    },
    "required": ["state", "from", "steps"],
    "additionalProperties": False,
    "description": "run the node steps times, each step's output the next step's state",
}
GRAPH_FILE = {
    "type": "string",
    "pattern": r"\.ya?ml$",
    "description": "a subgraph: a graph file, relative to this one",
}
ESCAPED = {
    "type": "object",
    "properties": {"value": {}},
    "required": ["value"],
    "additionalProperties": False,
    "description": "a literal written as {value: ...}",
}


def _kind_schema(k: Kind) -> dict[str, Any]:
    base = k.base
    if typing.get_origin(base) is list:  # a nested list, e.g. list[list[float]]
        item: dict[str, Any] = _kind_schema(Kind(typing.get_args(base)[0], True))
    elif base is bool:
        item = {"type": "boolean"}
    elif base is int:
        item = {"type": "integer"}
    elif base is float:
        item = {"type": "number"}
    elif base is Vec3:
        item = {
            "type": "array",
            "items": {"anyOf": [{"type": "number"}, EXPR]},
            "minItems": 2,
            "maxItems": 3,
        }
    elif isinstance(base, type) and issubclass(base, enum.Enum):
        item = {"enum": [m.value for m in base]}
    elif isinstance(base, type) and issubclass(base, str):
        item = {"type": "string"}
    elif base is Faces:
        item = {
            "type": "array",
            "items": {"type": "array", "items": {"type": "integer"}, "minItems": 3},
        }
    elif getattr(base, "__name__", "") == "Points":
        coordinate = {"anyOf": [{"type": "number"}, EXPR]}
        point = {"type": "array", "items": coordinate, "minItems": 2, "maxItems": 3}
        item = {"type": "array", "items": {"anyOf": [point, EXPR]}}
    else:
        item = {}  # geometry: only through a wire or a param
    if k.is_list:
        inner = [WIRE, EXPR] + ([item] if item else [])
        return {"type": "array", "items": {"anyOf": inner}}
    return item


def port_schema(p: Port) -> dict[str, Any]:
    alternatives = [s for s in (_kind_schema(k) for k in p.type.kinds) if s]
    if p.type.optional:
        alternatives.append({"type": "null"})
    schema: dict[str, Any] = {"anyOf": [WIRE, EXPR, ESCAPED, *alternatives]}
    doc = p.doc or ""
    schema["description"] = f"{p.type.name}. {doc}".strip()
    if not p.required and _jsonable(p.default):
        schema["default"] = _plain(p.default)
    return schema


def _plain(value: Any) -> Any:
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _jsonable(value: Any) -> bool:
    return isinstance(_plain(value), (int, float, str, bool, list, type(None)))


def json_schema() -> dict[str, Any]:
    """A JSON Schema (draft 2020-12) of the graph format, for editor completion."""
    registry = node_types()
    branches = []
    for name, spec in registry.items():
        branches.append(
            {
                "if": {"properties": {"type": {"const": name}}, "required": ["type"]},
                "then": {
                    "description": spec.summary,
                    "properties": {
                        "type": {"const": name},
                        "repeat": REPEAT,
                        "simulate": SIMULATE,
                        **{p.name: port_schema(p) for p in spec.inputs.values()},
                    },
                    # a simulated node may leave its state input out
                    "anyOf": [
                        {
                            "required": [
                                "type",
                                *[p.name for p in spec.inputs.values() if p.required],
                            ]
                        },
                        {"required": ["type", "simulate"]},
                    ],
                    "additionalProperties": False,
                },
            }
        )
    param_long = {
        "type": "object",
        "properties": {
            "default": {},
            "min": {"type": "number"},
            "max": {"type": "number"},
            "doc": {"type": "string"},
            "type": {"type": "string"},
            "choices": {
                "type": "array",
                "minItems": 1,
                "items": {"type": ["number", "string", "boolean"]},
            },
        },
        "additionalProperties": False,
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://formgraph.invalid/schema/graph-1.json",
        "title": "formgraph graph",
        "type": "object",
        "required": ["formgraph", "nodes"],
        "additionalProperties": False,
        "properties": {
            "formgraph": {"const": 1, "description": "format version"},
            "description": {"type": "string"},
            "params": {
                "type": "object",
                "additionalProperties": {
                    "anyOf": [param_long, {"type": ["number", "string", "boolean", "array"]}]
                },
            },
            "outputs": {
                "type": "object",
                "additionalProperties": WIRE,
                "description": "the outputs of this graph when another uses it as a node",
            },
            "nodes": {
                "type": "object",
                "additionalProperties": {
                    "type": "object",
                    "required": ["type"],
                    "properties": {
                        "type": {"anyOf": [{"enum": list(registry)}, GRAPH_FILE]},
                        "repeat": REPEAT,
                        "simulate": SIMULATE,
                    },
                    "allOf": branches,
                },
            },
        },
    }


def _default_text(p: Port) -> str:
    if p.default is REQUIRED:
        return "required"
    d = _plain(p.default)
    if isinstance(d, bool):
        return "true" if d else "false"
    if isinstance(d, list):
        return "[" + ", ".join(f"{x:g}" if isinstance(x, float) else str(x) for x in d) + "]"
    if d is None:
        return "none"
    return f"{d:g}" if isinstance(d, float) else str(d)


def _type_text(t: PortType) -> str:
    e = t.enum
    if e is not None:
        return " | ".join(repr(m.value) for m in e)
    return t.name + (" | None" if t.optional else "")


def _out_text(t: PortType) -> str:
    """An output type; one that follows an input says so."""
    return f"same type as {t.same_as}" if t.same_as else t.name


def node_text(spec: NodeSpec) -> str:
    """One node type's ports and outputs, for ``formgraph nodes TYPE``."""
    lines = [f"{spec.name}  (version {spec.version})", "", spec.summary, "", "inputs:"]
    for p in spec.inputs.values():
        lines.append(f"  {p.name:<12} {_type_text(p.type):<24} [{_default_text(p)}]  {p.doc}")
    lines.append("outputs:")
    for name, t in spec.outputs.items():
        label = "(single)" if not spec.multi_output else name
        lines.append(f"  {label:<12} {_out_text(t)}")
    return "\n".join(lines)


def catalogue_text() -> str:
    """Every node type, one line each, grouped by family."""
    out: list[str] = []
    family = None
    for name, spec in node_types().items():
        if spec.family != family:
            family = spec.family
            out.append(f"\n{family}" if out else family)
        ports = ", ".join(p.name if p.required else f"[{p.name}]" for p in spec.inputs.values())
        ret = " | ".join(_out_text(t) for t in spec.outputs.values())
        out.append(f"  {name}({ports}) -> {ret}\n      {spec.summary}")
    return "\n".join(out)


def markdown() -> str:
    """The node catalogue as Markdown (``docs/nodes.md``)."""
    lines = [
        "# Node catalogue",
        "",
        "Generated from the registry by `formgraph nodes --markdown`; do not edit by hand.",
        "Angles are in degrees; a coordinate given as [x, y] gets z = 0.",
        "",
    ]
    registry = node_types()
    families = sorted({s.family for s in registry.values()})
    lines.append("Families: " + ", ".join(f"[{f}](#{f})" for f in families) + ".")
    family = None
    for name, spec in registry.items():
        if spec.family != family:
            family = spec.family
            lines += ["", f"## {family}", ""]
        ret = ", ".join(
            f"{k}: {_out_text(t)}" if spec.multi_output else _out_text(t)
            for k, t in spec.outputs.items()
        )
        lines += [f"### `{name}` -> {ret}", "", spec.summary, ""]
        if spec.inputs:
            lines += ["| input | type | default | description |", "|---|---|---|---|"]
            for p in spec.inputs.values():
                doc = p.doc.replace("|", "\\|")
                ty = _type_text(p.type).replace("|", "\\|")
                lines.append(f"| `{p.name}` | {ty} | {_default_text(p)} | {doc} |")
            lines.append("")
    return "\n".join(lines).rstrip() + "\n"


BEGIN = "<!-- catalogue:begin (generated: python -m formgraph.language.catalogue README.md) -->"
END = "<!-- catalogue:end -->"


def readme_table() -> str:
    """The compact catalogue the README shows: one row per node type."""
    rows = ["| node | inputs ([optional]) | output | what it does |", "|---|---|---|---|"]
    for name, spec in node_types().items():
        ports = ", ".join(p.name if p.required else f"[{p.name}]" for p in spec.inputs.values())
        ret = ", ".join(_out_text(t) for t in spec.outputs.values())
        summary = spec.summary.replace("|", "\\|")
        rows.append(f"| `{name}` | {ports} | {ret} | {summary} |")
    return "\n".join(rows)


def update_readme(path: str) -> bool:
    """Rewrite the generated catalogue section of ``path``; True when it changed."""
    from pathlib import Path

    p = Path(path)
    text = p.read_text(encoding="utf-8")
    start, end = text.index(BEGIN), text.index(END)
    new = text[:start] + BEGIN + "\n" + readme_table() + "\n" + text[end:]
    if new != text:
        p.write_text(new, encoding="utf-8")
    return new != text


if __name__ == "__main__":  # pragma: no cover
    import sys

    for arg in sys.argv[1:]:
        print(f"{arg}: {'updated' if update_readme(arg) else 'current'}")
