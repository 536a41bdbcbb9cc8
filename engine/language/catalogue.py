"""Everything generated from the registry: the JSON Schema, the text catalogue and the docs.

``formgraph schema`` prints :func:`json_schema`; ``formgraph nodes`` prints
:func:`catalogue_text` / :func:`node_text`, and ``formgraph nodes --markdown`` the whole
catalogue as one Markdown file (:func:`markdown`). The documentation site's node reference
is built from the same functions at every build (``docs/hooks.py``): :func:`index_markdown`
and one :func:`family_markdown` page per family, so a new node is documented by its own
docstring and signature, with no page to edit.
"""

from __future__ import annotations

import enum
import importlib
import re
import typing
from collections.abc import Callable
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


def families() -> dict[str, list[NodeSpec]]:
    """Every registered node type by family (the part of its name before the dot), sorted."""
    out: dict[str, list[NodeSpec]] = {}
    for spec in node_types().values():
        out.setdefault(spec.family, []).append(spec)
    return out


_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
_SECTION = re.compile(r"^(\w[\w ]*)\n-{3,}$", re.M)


def _module_doc(name: str) -> str:
    """The first paragraph of a module's docstring, on one line ('' if there is none)."""
    try:
        doc = importlib.import_module(name).__doc__ or ""
    except ImportError:
        return ""
    return " ".join(_ROLE.sub(r"``\1``", doc).strip().split("\n\n", 1)[0].split())


def _source(spec: NodeSpec) -> str:
    """Where a node's code is, as a path in the repository (``nodes/mesh/offset.py``)."""
    module = spec.func.__module__
    prefix = "formgraph.nodes."
    if module.startswith(prefix):
        return "nodes/" + module[len(prefix) :].replace(".", "/") + ".py"
    return module


def _doc_sections(doc: str) -> tuple[str, dict[str, str]]:
    """A numpydoc docstring as its prose (before the first section) and its sections."""
    doc = _ROLE.sub(lambda m: f"``{m.group(1)}``", doc)
    heads = list(_SECTION.finditer(doc))
    prose = doc[: heads[0].start()] if heads else doc
    sections = {}
    for i, h in enumerate(heads):
        end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
        sections[h.group(1)] = doc[h.end() : end].strip("\n")
    return prose.strip(), sections


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def node_markdown(
    spec: NodeSpec,
    level: int = 3,
    see_also: Callable[[NodeSpec], str] | None = None,
    anchor: bool = False,
) -> str:
    """One node type as Markdown: its doc, a table of its inputs (type, default, doc), its
    outputs and its other docstring sections (an example). ``see_also(spec)`` adds a line of
    links (the site's manual pages and examples that use the node); ``anchor`` gives the
    heading the node's name as its id (``{ #mesh.box }``, Markdown's attribute lists)."""
    prose, sections = _doc_sections(spec.doc)
    head = f"{'#' * level} `{spec.name}`" + (f" {{ #{spec.name} }}" if anchor else "")
    lines = [head, "", prose, ""]
    if spec.inputs:
        lines += ["| input | type | default | description |", "|---|---|---|---|"]
        for p in spec.inputs.values():
            ty = _cell(_type_text(p.type))
            lines.append(f"| `{p.name}` | {ty} | {_cell(_default_text(p))} | {_cell(p.doc)} |")
        lines.append("")
    if spec.multi_output:
        outs = ", ".join(f"`{k}` ({_out_text(t)})" for k, t in spec.outputs.items())
        lines += [f"**Outputs:** {outs}, wired as `@node.output`.", ""]
    else:
        lines += [f"**Output:** {_out_text(next(iter(spec.outputs.values())))}.", ""]
    for title, body in sections.items():
        if title == "Parameters":  # the inputs' table says it
            continue
        lines += [f"**{title}:** " + " ".join(body.split()), ""]
    lines += [f"Version {spec.version}; the code: `{_source(spec)}`.", ""]
    if see_also is not None and (extra := see_also(spec)):
        lines += [extra, ""]
    return "\n".join(lines)


def _ports_text(spec: NodeSpec) -> str:
    return ", ".join(p.name if p.required else f"[{p.name}]" for p in spec.inputs.values())


def _family_doc(family: str) -> str:
    """A family package's docstring (``nodes/<family>/__init__.py``), paragraphs kept."""
    try:
        doc = importlib.import_module(f"formgraph.nodes.{family}").__doc__ or ""
    except ImportError:
        return ""
    doc = _ROLE.sub(r"``\1``", doc)
    return "\n\n".join(" ".join(par.split()) for par in doc.strip().split("\n\n"))


def family_markdown(
    family: str, see_also: Callable[[NodeSpec], str] | None = None, intro: str = ""
) -> str:
    """The reference page of one family: its package's docstring, a table of its nodes, then
    every node (:func:`node_markdown`) under the module that defines it."""
    specs = families()[family]
    lines = [f"# {family}", "", _family_doc(family), ""]
    if intro:
        lines += [intro, ""]
    lines += [
        f"Generated from the registry at every build: each node's signature and docstring "
        f"(the code is in `nodes/{family}/`).",
        "",
        "| node | inputs ([optional]) | output | what it does |",
        "|---|---|---|---|",
    ]
    for spec in specs:
        ret = ", ".join(_out_text(t) for t in spec.outputs.values())
        lines.append(
            f"| [`{spec.name}`](#{spec.name}) | {_cell(_ports_text(spec))} | {_cell(ret)} "
            f"| {_cell(spec.summary)} |"
        )
    lines.append("")
    by_module: dict[str, list[NodeSpec]] = {}
    for spec in specs:
        by_module.setdefault(spec.func.__module__, []).append(spec)
    # the modules in the order the package's docstring names them (``primitives``, ...)
    doc = _family_doc(family)

    def place(module: str) -> tuple[int, str]:
        at = doc.find(f"``{module.rsplit('.', 1)[-1]}``")
        return (at if at >= 0 else len(doc), module)

    for module in sorted(by_module, key=place):
        members = by_module[module]
        topic = module.rsplit(".", 1)[-1]
        lines += [
            f"## {topic}",
            "",
            _module_doc(module),
            "",
            f"The code: `{_source(members[0])}`.",
            "",
        ]
        for spec in members:
            lines.append(node_markdown(spec, 3, see_also, anchor=True))
    return "\n".join(lines).rstrip() + "\n"


def index_markdown() -> str:
    """The node reference's first page: every family with a one-line row per node."""
    lines = [
        "# Node reference",
        "",
        "Every node type, generated from the registry at every build (a node added to "
        "`nodes/` appears here with no page to edit). A family is the part of a node's name "
        "before the dot, and its code is the package of that name under `nodes/`; "
        "`formgraph nodes TYPE` prints one node's ports, `formgraph nodes --markdown` the "
        "whole catalogue as one file. Angles are in degrees; a coordinate given as [x, y] "
        "gets z = 0.",
        "",
    ]
    for family, specs in families().items():
        summary = _family_doc(family).split("\n\n", 1)[0]
        lines += [f"## [{family}]({family}.md)", "", summary, ""]
        lines += ["| node | inputs ([optional]) | what it does |", "|---|---|---|"]
        for spec in specs:
            lines.append(
                f"| [`{spec.name}`]({family}.md#{spec.name}) | {_cell(_ports_text(spec))} "
                f"| {_cell(spec.summary)} |"
            )
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def markdown() -> str:
    """The whole node catalogue as one Markdown file (``formgraph nodes --markdown``)."""
    lines = [
        "# Node catalogue",
        "",
        "Generated from the registry by `formgraph nodes --markdown`.",
        "Angles are in degrees; a coordinate given as [x, y] gets z = 0.",
        "",
    ]
    groups = families()
    lines.append("Families: " + ", ".join(f"[{f}](#{f})" for f in sorted(groups)) + ".")
    for family, specs in groups.items():
        lines += ["", f"## {family}", "", _family_doc(family), ""]
        lines += [node_markdown(spec, 3) for spec in specs]
    return "\n".join(lines).rstrip() + "\n"
