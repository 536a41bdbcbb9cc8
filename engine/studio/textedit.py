"""The canvas's edits as minimal edits of a graph's YAML text.

Each gesture on the studio's canvas (a wire drawn or cut, a node added, deleted, renamed or
moved) becomes a few :class:`Edit` s, each replacing one span of the text: the spans are
found on the text composed by PyYAML (every node's line and column), and nothing outside
them changes, so comments, key order, flow style, quoting and blank lines elsewhere stay
byte for byte. The page applies them through the editor (Monaco's ``executeEdits``), whose
undo then undoes them.

Why not ruamel.yaml's round trip: loaded and dumped with no edit at all (``preserve_quotes``,
width 4096), it changed 5 of the 26 graphs in ``graphs/`` (23 lines: flow lists re-wrapped,
block lists re-indented); edits on the text by position change none by construction (the
tests check it on every graph there).

Positions on the canvas live in a ``layout:`` section (``name: [x, y]``, one line a node),
which the checker reads but never checks and no cache key includes.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import yaml

from formgraph.language import yamlread

__all__ = [
    "Edit",
    "EditError",
    "add_node",
    "apply",
    "delete_node",
    "merged",
    "move_nodes",
    "positions",
    "rename_node",
    "unwire",
    "wire",
]

INDENT = 2  # a new section's indentation, when the file shows none to follow
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*\Z")  # a node, param or port name
TYPE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_./-]*\Z")  # a node type (a subgraph's file)


class EditError(ValueError):
    """An edit the text cannot take; the message is a sentence for the page."""


@dataclass(frozen=True)
class Edit:
    """Replace ``text[start:end]`` (character offsets) with ``new``."""

    start: int
    end: int
    new: str

    def where(self, text: str) -> dict[str, int | str]:
        """The edit as Monaco takes it: 1-based lines, columns in UTF-16 code units."""

        def at(offset: int) -> tuple[int, int]:
            line = text.count("\n", 0, offset)
            start = text.rfind("\n", 0, offset) + 1
            return line + 1, len(text[start:offset].encode("utf-16-le")) // 2 + 1

        (l0, c0), (l1, c1) = at(self.start), at(self.end)
        return {"line0": l0, "col0": c0, "line1": l1, "col1": c1, "text": self.new}


def merged(edits: Iterable[Edit]) -> list[Edit]:
    """``edits`` in text order, insertions at one place joined in the order given (an
    editor applying several at one place may order them either way)."""
    ordered = sorted(enumerate(edits), key=lambda ie: (ie[1].start, ie[1].end, ie[0]))
    out: list[Edit] = []
    for _, e in ordered:
        last = out[-1] if out else None
        if last is not None and last.start == last.end == e.start:
            out[-1] = Edit(last.start, e.end, last.new + e.new)
        elif last is not None and e.start < last.end:
            raise EditError("two edits of one gesture overlap")  # (a bug: never shown)
        else:
            out.append(e)
    return out


def apply(text: str, edits: Iterable[Edit]) -> str:
    """``text`` with ``edits`` made (see :func:`merged`)."""
    out = text
    for e in reversed(merged(edits)):
        out = out[: e.start] + e.new + out[e.end :]
    return out


# ------------------------------------------------------------------------ the composed text


class _Doc:
    """The text composed (no number arrays lifted: the marks are the text's own)."""

    def __init__(self, text: str, within: tuple[int, int, int] | None = None):
        self.text = text
        self.window: yaml.MappingNode | None = None
        if within is not None:
            self.window = self._window(*within)
            if self.window is not None:  # (offsets are asked within its lines only)
                self.root, self._at = self.window, within
                self._local = [0] + [
                    m.end() for m in re.finditer("\n", text[within[0] : within[1]])
                ]
                return
        try:
            root = yaml.compose(text, Loader=yamlread.Loader)
        except yaml.YAMLError as exc:
            raise EditError(
                f"the text is not valid YAML here ({exc.__class__.__name__}); "
                "fix it in the editor first"
            ) from None
        if not isinstance(root, yaml.MappingNode):
            raise EditError("the text is not a graph (a mapping with 'nodes:')")
        self.root = root
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def _window(self, start: int, end: int, line: int) -> yaml.MappingNode | None:
        """The lines ``text[start:end]`` (one node's, its key on 0-based ``line``) composed
        at their own line numbers: the node's entry, when they hold exactly one block entry
        (else None: the whole text is composed)."""
        try:
            root = yaml.compose("\n" * line + self.text[start:end], Loader=yamlread.Loader)
        except yaml.YAMLError:
            return None
        if not isinstance(root, yaml.MappingNode) or root.flow_style or len(root.value) != 1:
            return None
        key = root.value[0][0]
        if not isinstance(key, yaml.ScalarNode) or key.start_mark.line != line:
            return None
        return root

    def offset(self, mark: yaml.Mark) -> int:
        """A mark's character offset, from its line and column."""
        if self.window is not None:
            start, _, line = self._at
            return min(start + self._local[mark.line - line] + mark.column, len(self.text))
        return (
            min(self.starts[mark.line] + mark.column, len(self.text))
            if mark.line < len(self.starts)
            else len(self.text)
        )

    def section(self, name: str) -> tuple[yaml.Node, yaml.Node] | None:
        for k, v in self.root.value:
            if isinstance(k, yaml.ScalarNode) and k.value == name:
                return k, v
        return None

    def nodes(self) -> yaml.MappingNode:
        if self.window is not None:  # one node's lines: the nodes mapping's entry for it
            return self.window
        found = self.section("nodes")
        if found is None or not isinstance(found[1], yaml.MappingNode):
            raise EditError("the graph has no 'nodes:' mapping to edit")
        if found[1].flow_style:
            raise EditError(
                "'nodes:' is written in flow style ({...}); the canvas edits the block style only"
            )
        return found[1]

    def node(self, name: str) -> tuple[yaml.Node, yaml.MappingNode]:
        for k, v in self.nodes().value:
            if isinstance(k, yaml.ScalarNode) and k.value == name:
                if not isinstance(v, yaml.MappingNode):
                    raise EditError(f"node '{name}' is not a mapping")
                return k, v
        raise EditError(f"there is no node '{name}'")

    # -------------------------------------------------------------------- lines and spans

    def line_start(self, offset: int) -> int:
        return self.text.rfind("\n", 0, offset) + 1

    def line_end(self, offset: int) -> int:
        """The offset just past the newline ending the line at ``offset`` (or the end)."""
        i = self.text.find("\n", offset)
        return len(self.text) if i < 0 else i + 1

    def last_end(self, node: yaml.Node) -> int:
        """Where a node's written content ends: block collections' end marks run on to the
        next token (over blank lines and comments), so their last leaf's end is taken."""
        if isinstance(node, (yaml.MappingNode, yaml.SequenceNode)) and not node.flow_style:
            items = node.value
            if not items:
                return self.offset(node.start_mark)
            last = items[-1][1] if isinstance(node, yaml.MappingNode) else items[-1]
            return self.last_end(last)
        end = self.offset(node.end_mark)
        if isinstance(node, yaml.ScalarNode) and node.style in ("|", ">"):
            while end > 0 and self.text[end - 1] == "\n":
                end -= 1  # a block scalar's mark is past its last line break
        return end

    def entry_lines(self, key: yaml.Node, value: yaml.Node) -> tuple[int, int]:
        """The whole lines a block mapping entry is written on (its own comments kept)."""
        return self.line_start(self.offset(key.start_mark)), self.line_end(self.last_end(value))

    def indent_of(self, node: yaml.Node) -> int:
        return node.start_mark.column


def _quoted(value: str) -> str:
    """``value`` as a double-quoted YAML scalar (JSON's escapes are YAML's)."""
    return json.dumps(value, ensure_ascii=False)


def _name(text: str, what: str = "name") -> str:
    """``text`` if it can be written as a key as it is (a request's names are not trusted)."""
    if not isinstance(text, str) or not NAME.match(text):
        raise EditError(f"{text!r} is not a {what} the canvas can write")
    return text


def _key_indent(doc: _Doc, mapping: yaml.MappingNode, fallback: int) -> int:
    return doc.indent_of(mapping.value[0][0]) if mapping.value else fallback


def _add_entry(doc: _Doc, mapping: yaml.MappingNode, key: str, value: str, indent: int) -> Edit:
    """An entry ``key: value`` appended to a block mapping (or a flow one's braces)."""
    if mapping.flow_style:
        end = doc.offset(mapping.end_mark) - 1  # the closing brace
        sep = ", " if mapping.value else ""
        return Edit(end, end, f"{sep}{key}: {value}")
    last = mapping.value[-1]
    at = doc.entry_lines(*last)[1]
    lead = "" if at == 0 or doc.text[at - 1] == "\n" else "\n"
    return Edit(at, at, f"{lead}{' ' * indent}{key}: {value}\n")


# ------------------------------------------------------------------------------ wires


def wire(
    text: str,
    src: str,
    output: str,
    dst: str,
    port: str,
    *,
    listed: bool = False,
    ref: str | None = None,
    within: tuple[int, int, int] | None = None,
) -> list[Edit]:
    """Wire ``src`` (its ``output``, or its only one for "") into ``dst``'s ``port``.

    An absent port gains an entry; a port holding a value has it replaced, unless the port
    takes a list (``listed``): then the list gains an element (a single wire there becomes a
    list of both). ``ref`` is the value to write instead of the wire (a param's
    ``"=name"``). ``within`` is where ``dst`` is written (see
    :func:`formgraph.language.incremental.node_span`): only those lines are composed.
    """
    _name(port, "port name")
    doc = _Doc(text, within)
    if doc.window is not None and doc.window.value[0][0].value != dst:
        doc = _Doc(text)  # (not dst's lines: the whole text says where dst is)
    ref = _quoted(ref if ref is not None else f"@{src}.{output}" if output else f"@{src}")
    _, body = doc.node(dst)
    for k, v in body.value:
        if not (isinstance(k, yaml.ScalarNode) and k.value == port):
            continue
        if listed and isinstance(v, yaml.SequenceNode):
            return [_append_item(doc, v, ref)]
        start, end = doc.offset(v.start_mark), doc.last_end(v)
        if listed and isinstance(v, yaml.ScalarNode) and str(v.value).startswith("@"):
            return [Edit(start, end, f"[{doc.text[start:end]}, {ref}]")]
        return [Edit(start, end, ref)]
    indent = _key_indent(doc, body, doc.indent_of(body) + INDENT)
    return [_add_entry(doc, body, port, f"[{ref}]" if listed else ref, indent)]


def _append_item(doc: _Doc, seq: yaml.SequenceNode, item: str) -> Edit:
    if seq.flow_style or not seq.value:
        end = doc.offset(seq.end_mark) - 1  # the closing bracket
        if not seq.flow_style:  # an empty block list cannot be: YAML writes it as []
            raise EditError("an empty block list cannot take an element here")
        return Edit(end, end, f"{', ' if seq.value else ''}{item}")
    first = seq.value[0]
    col = doc.indent_of(first)
    dash = doc.text.rfind(
        "-", doc.line_start(doc.offset(first.start_mark)), doc.offset(first.start_mark)
    )
    dash_col = dash - doc.line_start(dash) if dash >= 0 else max(col - 2, 0)
    at = doc.line_end(doc.last_end(seq.value[-1]))
    lead = "" if doc.text[at - 1] == "\n" else "\n"
    return Edit(at, at, f"{lead}{' ' * dash_col}- {item}\n")


def _refers(value: str, name: str, output: str | None = None) -> bool:
    if output is None:
        return value == f"@{name}" or value.startswith(f"@{name}.")
    return value == (f"@{name}.{output}" if output else f"@{name}")


def unwire(text: str, src: str, output: str, dst: str, port: str) -> list[Edit]:
    """Cut the wire from ``src`` (``output``, "" for none) into ``dst``'s ``port``: the
    port's entry goes, or the element of its list. What the port then lacks, the checker
    says."""
    doc = _Doc(text)
    _, body = doc.node(dst)
    for k, v in body.value:
        if not (isinstance(k, yaml.ScalarNode) and k.value == port):
            continue
        if isinstance(v, yaml.ScalarNode) and _wired(v.value, src, output):
            if body.flow_style:
                return [_flow_entry_span(doc, body, k, v)]
            start, end = doc.entry_lines(k, v)
            return [Edit(start, end, "")]
        if isinstance(v, yaml.SequenceNode):
            for i, item in enumerate(v.value):
                if isinstance(item, yaml.ScalarNode) and _wired(item.value, src, output):
                    return [_item_span(doc, v, i)]
    raise EditError(f"no wire from '{src}' into '{dst}.{port}' to cut")


def _wired(value: str, src: str, output: str) -> bool:
    return _refers(value, src, output) or (not output and _refers(value, src))


def _item_span(doc: _Doc, seq: yaml.SequenceNode, i: int) -> Edit:
    item = seq.value[i]
    if not seq.flow_style:
        line = doc.line_start(doc.offset(item.start_mark))
        return Edit(line, doc.line_end(doc.last_end(item)), "")
    start, end = doc.offset(item.start_mark), doc.last_end(item)
    if i + 1 < len(seq.value):  # the item and the separator after it
        return Edit(start, doc.offset(seq.value[i + 1].start_mark), "")
    if i > 0:  # the last: the separator before it
        return Edit(doc.last_end(seq.value[i - 1]), end, "")
    return Edit(start, end, "")


def _flow_entry_span(doc: _Doc, body: yaml.MappingNode, k: yaml.Node, v: yaml.Node) -> Edit:
    keys = [kk for kk, _ in body.value]
    i = keys.index(k)
    start, end = doc.offset(k.start_mark), doc.last_end(v)
    if i + 1 < len(keys):
        return Edit(start, doc.offset(keys[i + 1].start_mark), "")
    if i > 0:
        return Edit(doc.last_end(body.value[i - 1][1]), end, "")
    return Edit(start, end, "")


# ------------------------------------------------------------------------------ nodes


def add_node(
    text: str,
    name: str,
    type_name: str,
    placeholders: Sequence[str] = (),
    at: tuple[float, float] | None = None,
) -> list[Edit]:
    """A node ``name`` of ``type_name`` at the end of ``nodes:``, each of ``placeholders``
    (its required inputs) written ``port: ~`` for the checker to report, and its place
    ``at`` in ``layout:``."""
    _name(name, "node name")
    if not TYPE.match(type_name):
        raise EditError(f"{type_name!r} is not a node type the canvas can write")
    for p in placeholders:
        _name(p, "port name")
    doc = _Doc(text)
    nodes = doc.nodes()
    if any(isinstance(k, yaml.ScalarNode) and k.value == name for k, _ in nodes.value):
        raise EditError(f"there is already a node '{name}'")
    indent = _key_indent(doc, nodes, INDENT)
    inner = INDENT
    for _, v in nodes.value:  # the body indentation the file uses
        if isinstance(v, yaml.MappingNode) and v.value and not v.flow_style:
            inner = doc.indent_of(v.value[0][0]) - doc.indent_of(nodes.value[0][0])
            break
    pad = " " * (indent + max(inner, 1))
    lines = [f"{' ' * indent}{name}:", f"{pad}type: {type_name}"]
    lines += [f"{pad}{p}: ~" for p in placeholders]
    if nodes.value:
        at_line = doc.entry_lines(*nodes.value[-1])[1]
        lead = "" if doc.text[at_line - 1] == "\n" else "\n"
        edits = [Edit(at_line, at_line, lead + "\n".join(lines) + "\n")]
    else:  # `nodes: {}` or an empty `nodes:`
        k, v = doc.section("nodes")  # type: ignore[misc]
        start = doc.offset(k.end_mark) + 1  # after the colon
        end = doc.last_end(v) if v.value or v.flow_style else start
        edits = [Edit(start, end, "\n" + "\n".join(lines))]
    if at is not None:
        edits += _layout_edits(doc, {name: at})
    return edits


def delete_node(text: str, name: str) -> list[Edit]:
    """Node ``name``'s lines go (and its ``layout:`` entry); the wires that led from it
    stay, for the checker to report."""
    doc = _Doc(text)
    k, v = doc.node(name)
    if len(doc.nodes().value) == 1:
        raise EditError("a graph keeps at least one node (delete it in the editor)")
    start, end = doc.entry_lines(k, v)
    edits = [Edit(start, end, "")]
    layout = doc.section("layout")
    if layout is not None and isinstance(layout[1], yaml.MappingNode):
        edits += [
            _entry_removal(doc, layout[1], lk, lv)
            for lk, lv in layout[1].value
            if isinstance(lk, yaml.ScalarNode) and lk.value == name
        ]
    return edits


def _entry_removal(doc: _Doc, mapping: yaml.MappingNode, k: yaml.Node, v: yaml.Node) -> Edit:
    if mapping.flow_style:
        return _flow_entry_span(doc, mapping, k, v)
    return Edit(*doc.entry_lines(k, v), "")


def rename_node(text: str, old: str, new: str) -> list[Edit]:
    """Node ``old`` becomes ``new``: its key, every wire to it (``"@old"``, ``"@old.x"``
    anywhere in the file: inputs, lists, ``outputs:``, ``repeat:``) and its ``layout:``
    entry, each scalar rewritten in its own quoting."""
    if not NAME.match(new) or new.startswith("_") or not new.replace("-", "_").isidentifier():
        raise EditError(
            f"'{new}' is not a node name (letters, digits, '_' and '-', not starting with a digit)"
        )
    doc = _Doc(text)
    key, _ = doc.node(old)
    names = {k.value for k, _ in doc.nodes().value if isinstance(k, yaml.ScalarNode)}
    params = doc.section("params")
    if params is not None and isinstance(params[1], yaml.MappingNode):
        names |= {k.value for k, _ in params[1].value if isinstance(k, yaml.ScalarNode)}
    if new in names and new != old:
        raise EditError(f"the name '{new}' is taken")
    edits = [Edit(doc.offset(key.start_mark), doc.offset(key.end_mark), new)]
    layout = doc.section("layout")
    if layout is not None and isinstance(layout[1], yaml.MappingNode):
        for lk, _ in layout[1].value:
            if isinstance(lk, yaml.ScalarNode) and lk.value == old:
                edits.append(Edit(doc.offset(lk.start_mark), doc.offset(lk.end_mark), new))
    for scalar in _scalars(doc.root):
        value = scalar.value
        if isinstance(value, str) and _refers(value, old):
            new_value = f"@{new}{value[len(old) + 1 :]}"
            start, end = doc.offset(scalar.start_mark), doc.offset(scalar.end_mark)
            if scalar.style == "'":
                written = "'" + new_value.replace("'", "''") + "'"
            else:
                written = _quoted(new_value)
            edits.append(Edit(start, end, written))
    return edits


def _scalars(node: yaml.Node) -> Iterable[yaml.ScalarNode]:
    stack = [node]
    seen: set[int] = set()
    while stack:
        n = stack.pop()
        if id(n) in seen:
            continue  # an alias: its scalars are written once, at the anchor
        seen.add(id(n))
        if isinstance(n, yaml.ScalarNode):
            yield n
        elif isinstance(n, yaml.SequenceNode):
            stack.extend(n.value)
        elif isinstance(n, yaml.MappingNode):
            for _, v in n.value:  # keys are names, not wires
                stack.append(v)


# ----------------------------------------------------------------------------- layout


def positions(text: str) -> dict[str, tuple[float, float]]:
    """The ``layout:`` positions ``text`` holds (as the checker reads them)."""
    from formgraph.language.yamlio import layout_of

    doc = _Doc(text)
    found = doc.section("layout")
    return layout_of(found[1]) if found is not None else {}


def move_nodes(text: str, where: Mapping[str, tuple[float, float]]) -> list[Edit]:
    """Set nodes' positions in ``layout:`` (made at the end of the file when absent)."""
    return _layout_edits(_Doc(text), where)


def _xy(p: tuple[float, float]) -> str:
    if not all(math.isfinite(c) for c in p):
        raise EditError("a position is two finite numbers")
    return f"[{round(p[0])}, {round(p[1])}]"


def _layout_edits(doc: _Doc, where: Mapping[str, tuple[float, float]]) -> list[Edit]:
    for name in where:
        _name(name, "node name")
    found = doc.section("layout")
    if found is None or (
        isinstance(found[1], yaml.ScalarNode) and found[1].value in ("", "~", "null")
    ):
        lines = "".join(f"{' ' * INDENT}{n}: {_xy(p)}\n" for n, p in where.items())
        if found is not None:  # `layout:` with nothing under it
            k, v = found
            at = doc.line_end(doc.offset(k.end_mark))
            start = doc.offset(k.start_mark)
            return [Edit(start, at, f"layout:\n{lines}")]
        end = len(doc.text)
        lead = "" if not doc.text or doc.text.endswith("\n") else "\n"
        return [Edit(end, end, f"{lead}layout:\n{lines}")]
    k, mapping = found
    if not isinstance(mapping, yaml.MappingNode):
        raise EditError("'layout:' is not a mapping of node name to [x, y]")
    edits = []
    existing = {lk.value: lv for lk, lv in mapping.value if isinstance(lk, yaml.ScalarNode)}
    indent = _key_indent(doc, mapping, INDENT)
    new = []
    for name, p in where.items():
        if name in existing:
            v = existing[name]
            edits.append(Edit(doc.offset(v.start_mark), doc.last_end(v), _xy(p)))
        else:
            new.append((name, p))
    if new:
        if mapping.flow_style or not mapping.value:
            end = doc.offset(mapping.end_mark) - 1
            body = ", ".join(f"{n}: {_xy(p)}" for n, p in new)
            edits.append(Edit(end, end, (", " if mapping.value else "") + body))
        else:
            at = doc.entry_lines(*mapping.value[-1])[1]
            lead = "" if doc.text[at - 1] == "\n" else "\n"
            body = "".join(f"{' ' * indent}{n}: {_xy(p)}\n" for n, p in new)
            edits.append(Edit(at, at, lead + body))
    return edits
