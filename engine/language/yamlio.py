"""Reading and writing graph files.

Reading uses PyYAML's safe loading only, through :mod:`formgraph.language.yamlread`
(libyaml, YAML 1.2 numbers, a cost bounded by what is accepted): the text is composed into a
node tree (to keep the line of every node and input), then each value is built, so a
``!!python/...`` tag is refused with its line. Duplicate keys, which YAML would silently
resolve to the last one, are reported; merge keys (``<<: *base``) are resolved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import yaml

from ..core.errors import Problem, Where
from ..core.types import TypeMismatch, describe, type_by_name
from . import yamlread
from .model import NodeDef, ParamDef

FORMAT_VERSION = 1
MAX_BYTES = 16 * 1024 * 1024
MAX_VALUES = 400_000  # scalars and collections, with aliases expanded: a few seconds to read
MAX_DEPTH = 64
TOP_KEYS = ("formgraph", "description", "params", "nodes", "outputs", "layout")


@dataclass
class Document:
    description: str = ""
    params: dict[str, ParamDef] = field(default_factory=dict)
    nodes: dict[str, NodeDef] = field(default_factory=dict)
    problems: list[Problem] = field(default_factory=list)
    outputs: dict[str, Any] = field(default_factory=dict)  # name -> wire, used as a subgraph
    output_lines: dict[str, int] = field(default_factory=dict)
    #: the top-level keys written, or None when the file could not be read as a mapping
    #: (not YAML, too large, ...): then its problems say all there is to say
    top_keys: tuple[str, ...] | None = None
    #: where the studio's canvas drew each node (``layout:``): read, never checked, and in
    #: no cache key (see :func:`layout_of`)
    layout: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: the values the text holds, with aliases expanded and as written (see
    #: :func:`.yamlread.expansion`): what an edit of one node adds to is known
    sizes: tuple[int, int] = (0, 0)


def _line(node: yaml.Node) -> int:
    return node.start_mark.line + 1


def parse(text: str, file: str = "<graph>") -> Document:
    """Parse graph text into a :class:`Document`; problems are collected, not raised."""
    doc = Document()

    def problem(
        message: str, line: int | None = None, node: str | None = None, input: str | None = None
    ) -> None:
        doc.problems.append(Problem(Where(file, line, node, input), message))

    if len(text.encode()) > MAX_BYTES:
        problem(f"the file is larger than {MAX_BYTES // (1024 * 1024)} MiB")
        return doc
    estimate = yamlread.estimate_values(text)
    if estimate > 2 * MAX_VALUES:  # well over the exact limit, which is checked after composing
        problem(
            f"the file holds about {estimate:,} values (numbers, strings, lists and mappings), "
            f"more than the {MAX_VALUES:,} a graph file may hold; a graph this large is better "
            f"built in Python"
        )
        return doc
    try:
        try:
            root, bulk = yamlread.compose(text)
            too_big, *sizes = yamlread.expansion(root, bulk, MAX_VALUES, MAX_DEPTH)
        except (yaml.YAMLError, ValueError):  # a lifted array was not a plain value: as written
            root, bulk = yaml.compose(text, Loader=yamlread.Loader), yamlread.Bulk()
            too_big, *sizes = yamlread.expansion(root, bulk, MAX_VALUES, MAX_DEPTH)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem(
            f"not valid YAML: {getattr(exc, 'problem', None) or exc}",
            mark.line + 1 if mark else None,
        )
        return doc
    except RecursionError:
        problem(f"the YAML is nested too deeply (more than {MAX_DEPTH} levels)")
        return doc
    if too_big:
        problem(too_big)
        return doc
    doc.sizes = (sizes[0], sizes[1])
    if root is None or not isinstance(root, yaml.MappingNode):
        problem("a graph file is a mapping with 'formgraph: 1' and 'nodes:'", 1)
        return doc

    top: dict[str, tuple[yaml.Node, yaml.Node]] = {}
    if not _merged(root, problem):
        return doc
    for k, v in root.value:
        key = _scalar_key(k)
        if key in top:
            problem(f"'{key}' appears twice", _line(k))
        elif key not in TOP_KEYS:
            problem(f"unknown top-level key '{key}' (expected {', '.join(TOP_KEYS)})", _line(k))
        top[key] = (k, v)
    doc.top_keys = tuple(top)

    if "formgraph" not in top:
        problem("missing 'formgraph: 1' (the format version)", 1)
    else:
        k, v = top["formgraph"]
        version = _value(v, problem, None, None)
        if isinstance(version, bool) or version != FORMAT_VERSION:
            problem(
                f"format version {version!r} is not supported (this formgraph reads "
                f"{FORMAT_VERSION})",
                _line(k),
            )

    if "description" in top:
        desc = _value(top["description"][1], problem, None, None)
        doc.description = "" if desc is None else str(desc)

    if "params" in top:
        k, v = top["params"]
        if isinstance(v, yaml.MappingNode):
            for pk, pv in v.value if _merged(v, problem) else ():
                name = _scalar_key(pk)
                if name in doc.params:
                    problem(f"param '{name}' is declared twice", _line(pk))
                    continue
                param = _param(name, pv, problem, bulk)
                if param is not None:
                    doc.params[name] = param
        elif not (isinstance(v, yaml.ScalarNode) and v.value in ("", "null", "~")):
            problem("'params' must be a mapping of name: default or name: {default: ...}", _line(k))

    if "outputs" in top:
        k, v = top["outputs"]
        if isinstance(v, yaml.MappingNode):
            for ok, ov in v.value:
                name = _scalar_key(ok)
                if name in doc.outputs:
                    problem(f"output '{name}' appears twice", _line(ok))
                doc.outputs[name] = _value(ov, problem, None, None)
                doc.output_lines[name] = _line(ok)
        else:
            problem("'outputs' must be a mapping of output name to a wire ('@node')", _line(k))

    if "layout" in top:
        _value(top["layout"][1], problem, None, None)  # (tags refused, as anywhere)
        doc.layout = layout_of(top["layout"][1])

    if "nodes" not in top:
        problem("missing 'nodes:' (a mapping of node name to its type and inputs)", 1)
        return doc
    k, v = top["nodes"]
    if not isinstance(v, yaml.MappingNode):
        problem("'nodes' must be a mapping of node name to {type: ..., inputs...}", _line(k))
        return doc
    for nk, nv in v.value if _merged(v, problem) else ():
        name = _scalar_key(nk)
        line = _line(nk)
        if name in doc.nodes:
            problem("node name appears twice", line, name)
            continue
        if not name.replace("-", "_").isidentifier():
            problem(
                "node names are letters, digits, '_' and '-', not starting with a digit", line, name
            )
        if name in doc.params:
            problem(f"the name '{name}' is both a param and a node", line, name)
        nd = node_def(name, line, nv, problem, bulk)
        if nd is not None:
            doc.nodes[name] = nd
    return doc


def node_def(
    name: str, line: int, nv: yaml.Node, problem: Any, bulk: yamlread.Bulk | None = None
) -> NodeDef | None:
    """The node ``name`` (its key on ``line``) from its composed body ``nv``; its problems
    go to ``problem(message, line, node, input)`` (None: the body is not a mapping)."""
    if not isinstance(nv, yaml.MappingNode):
        problem("a node is a mapping with 'type:' and its inputs", line, name)
        return None
    raw: dict[str, Any] = {}
    lines: dict[str, int] = {}
    unreadable: dict[str, str] = {}
    node_type = None
    for ik, iv in nv.value if _merged(nv, problem) else ():
        port = _scalar_key(ik)
        if port in raw or (port == "type" and node_type is not None):
            problem("input appears twice", _line(ik), name, port)
            continue
        bad: list[str] = []
        value = _value(iv, lambda msg, *a, bad=bad: bad.append(msg), name, port, bulk)
        if port == "type":
            node_type = value
            lines["type"] = _line(ik)  # an unknown type is reported at its own line
            bad and problem(bad[0], _line(ik), name)
            continue
        raw[port] = value
        lines[port] = _line(ik)
        if bad:
            unreadable[port] = bad[0]
    if node_type is not None and not isinstance(node_type, str):
        problem(
            f"'type' must be a node type name such as points.circle, got {describe(node_type)}",
            lines["type"],
            name,
        )
        node_type = ""
    elif not isinstance(node_type, str):
        problem("missing 'type:' (e.g. type: points.circle)", line, name)
        node_type = ""
    nd = NodeDef.make(name, node_type, raw, line, lines)
    nd.parse_errors.update(unreadable)
    return nd


def _merged(node: yaml.MappingNode, problem: Any) -> bool:
    """Resolve the merge keys (``<<: *base``) of a mapping in place; False when it cannot."""
    try:
        yamlread.Constructor().flatten_mapping(node)
    except yaml.YAMLError as exc:
        problem(f"cannot merge: {getattr(exc, 'problem', None) or exc}", _line(node))
        return False
    return True


def layout_of(node: yaml.Node) -> dict[str, tuple[float, float]]:
    """The node positions a ``layout:`` section holds (``name: [x, y]``).

    The section is the canvas's memory, not part of the graph: an entry that is not a name
    and two finite numbers is passed over without a problem (the canvas writes it again when
    the node is moved), and nothing here reaches a cache key.
    """
    out: dict[str, tuple[float, float]] = {}
    if not isinstance(node, yaml.MappingNode):
        return out
    for k, v in node.value:
        if not isinstance(k, yaml.ScalarNode) or not isinstance(v, yaml.SequenceNode):
            continue
        if v.tag != "tag:yaml.org,2002:seq":
            continue
        if len(v.value) != 2 or not all(isinstance(c, yaml.ScalarNode) for c in v.value):
            continue
        try:
            x, y = (float(c.value) for c in v.value)
        except ValueError:
            continue
        if math.isfinite(x) and math.isfinite(y):
            out[str(k.value)] = (x, y)
    return out


def _scalar_key(node: yaml.Node) -> str:
    return str(node.value) if isinstance(node, yaml.ScalarNode) else "<complex key>"


def _value(
    node: yaml.Node,
    problem: Any,
    where_node: str | None,
    port: str | None,
    bulk: yamlread.Bulk | None = None,
) -> Any:
    try:
        return yamlread.construct(node, bulk)
    except yaml.YAMLError as exc:
        why = getattr(exc, "problem", None) or exc
        hint = (
            ""
            if str(why).startswith("'") or "too long" in str(why)
            else (" (only plain YAML data is allowed; no !!python tags)")
        )
        problem(f"cannot read this value: {why}{hint}", _line(node), where_node, port)
        return None
    except (
        ValueError,
        TypeError,
        OverflowError,
        RecursionError,
        AttributeError,
        IndexError,
    ) as exc:
        # the safe constructor's own readers (e.g. a malformed !!binary or !!timestamp)
        problem(f"cannot read this value: {exc}", _line(node), where_node, port)
        return None


def _param(
    name: str, node: yaml.Node, problem: Any, bulk: yamlread.Bulk | None = None
) -> ParamDef | None:
    line = _line(node)
    value = _value(node, problem, None, None, bulk)
    if not isinstance(value, dict):
        return ParamDef(name, value, line=line)
    unknown = set(value) - {"default", "min", "max", "doc", "type", "choices"}
    stray = sorted(str(k) for k in unknown if value[k] is None and " " in str(k))
    if stray:  # {doc: degrees, bottom to top}: the ", " ended the text
        problem(
            f"param '{name}': the text {stray[0]!r} became a key of its own, because inside "
            "{...} a ', ' ends a value: put text that holds ', ' in quotes "
            f'(doc: "..., {stray[0]}")',
            line,
        )
        unknown -= set(stray)
    if unknown:
        problem(
            f"param '{name}': unknown key(s) {', '.join(sorted(map(str, unknown)))} "
            f"(expected default, min, max, doc, type, choices)",
            line,
        )
    p = ParamDef(
        name, value.get("default"), line=line, long_form=True, doc=str(value.get("doc", "") or "")
    )
    for bound in ("min", "max"):
        b = value.get(bound)
        if b is not None and (isinstance(b, bool) or not isinstance(b, (int, float))):
            problem(f"param '{name}': {bound} must be a number, got {b!r}", line)
        elif isinstance(b, float) and not math.isfinite(b):
            problem(f"param '{name}': {bound} must be a finite number, got {b!r}", line)
        else:
            setattr(p, bound, b)
    if "choices" in value:
        p.choices = read_choices(name, value["choices"], problem, line)
    if "type" in value:
        p.type_name = str(value["type"])
        try:
            p.type = type_by_name(p.type_name)
        except TypeMismatch as exc:
            problem(f"param '{name}': {exc}", line)
    elif "default" not in value:
        problem(f"param '{name}' needs a default (or a type, for geometry given from Python)", line)
    return p


def read_choices(name: str, raw: Any, problem: Any, line: int | None) -> tuple[Any, ...] | None:
    """A param's ``choices:``: a non-empty list of distinct numbers, texts or booleans."""
    if not isinstance(raw, list) or not raw:
        problem(f"param '{name}': choices must be a non-empty list, got {raw!r}", line)
        return None
    seen: list[Any] = []
    for c in raw:
        if not isinstance(c, (str, int, float, bool)):
            problem(f"param '{name}': a choice is a number, a text or true/false, got {c!r}", line)
            return None
        if any(type(c) is type(s) and c == s for s in seen):
            problem(f"param '{name}': the choice {c!r} is listed twice", line)
            return None
        seen.append(c)
    return tuple(seen)


def dump(
    description: str,
    params: dict[str, ParamDef],
    nodes: dict[str, NodeDef],
    outputs: dict[str, Any] | None = None,
) -> str:
    """The YAML text of a graph, in author order, that :func:`parse` reads back equal."""
    data: dict[str, Any] = {"formgraph": FORMAT_VERSION}
    if description:
        data["description"] = description
    if params:
        data["params"] = {n: p.to_yaml() for n, p in params.items()}
    if outputs:
        data["outputs"] = dict(outputs)
    data["nodes"] = {n: nd.to_yaml() for n, nd in nodes.items()}
    return yaml.safe_dump(
        data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=100
    )
