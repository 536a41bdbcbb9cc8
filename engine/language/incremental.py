"""A graph's text edited within one node: read and checked again where the edit reaches.

The studio's canvas edits the text one node at a time (a wire drawn into a port changes
that node's lines only). Reading the whole 500-node file again and checking every node
costs more than the recook the edit asks for; what changed is one node, and what its
change can reach is known:

- :func:`node_span`: the lines a node is written on (from its key to the next node's);
- :func:`reparse`: the edited text read as the text before it with that node's lines read
  again (composed alone, at their own line numbers); anything that could make the result
  differ from reading the whole text (an anchor, alias, tag or merge key in those lines, a
  change outside them, an old text that had problems) answers None, and the caller reads
  the whole text;
- :func:`recheck`: whether the edited graph has no problem, proved from the last clean
  check of the graph before it: the edited node, the nodes wired to it, the params (their
  inferred kinds) and the graph's outputs are checked again, the rest is the same nodes
  with the same upstream types as before. It answers False whenever it cannot prove it
  (a new cycle, an output type that changed, a subgraph node, any problem found): the
  caller then runs the whole check, whose list of problems is the one shown.

Nothing here decides anything the whole read and check would not: the tests compare both
on edits of every graph in ``graphs/``, including edits that break them.
"""

from __future__ import annotations

import copy
import functools
import re
from collections.abc import Mapping
from typing import Any

import yaml

from ..core.errors import Problem
from ..core.registry import node_types
from .check import Outline, _check_node, _check_outputs, output_type, param_problems
from .inference import expression_ports_take_text, infer_fed
from .model import NodeDef, Wire
from .subgraph import is_graph_type
from .yamlio import MAX_BYTES, MAX_DEPTH, MAX_VALUES, Document, node_def
from .yamlread import compose, estimate_values, expansion

__all__ = ["node_span", "recheck", "reparse"]

# what could make a node's lines mean something outside them, or read differently in
# context: anchors, aliases and tags (as tokens: '=a*b' and '=a * b' are not), merge keys,
# directives and document markers. (The sizes and the composing alone catch these too: an
# alias of the text before, or one the lines alone cannot resolve, is already refused; a
# false alarm only costs the whole read.)
_CONTEXTUAL = re.compile(r"(?:^|[\s\[{,])[&*!]\S|<<|^(?:%|---|\.\.\.)", re.MULTILINE)


@functools.lru_cache(maxsize=2)  # (a gesture asks for the lines of one text twice)
def _line_starts(text: str) -> list[int]:
    return [0] + [m.end() for m in re.finditer("\n", text)]


def node_span(text: str, nodes: Mapping[str, NodeDef], name: str) -> tuple[int, int, int] | None:
    """Where node ``name`` is written in ``text`` (the text ``nodes`` were read from):
    ``(start, end, line)``, character offsets of whole lines from its key to the next
    node's key (or to the next line at column 0 after the last node) and the 0-based line
    of its key; None when the lines are not known."""
    nd = nodes.get(name)
    if nd is None or nd.line is None:
        return None
    names = list(nodes)
    at = names.index(name)
    starts = _line_starts(text)
    first = nd.line - 1
    if at + 1 < len(names):
        nxt = nodes[names[at + 1]].line
        if nxt is None or nxt - 1 <= first or nxt - 1 >= len(starts):
            return None
        end = starts[nxt - 1]
    else:  # the last node: up to the next top-level line (a key, or a document's end)
        m = re.compile(r"^[^\s#]", re.MULTILINE).search(text, starts[first] + 1)
        end = m.start() if m else len(text)
    if first >= len(starts) or end <= starts[first]:
        return None
    return starts[first], end, first


def _window_node(
    window: str, line: int, name: str, file: str
) -> tuple[NodeDef, int, list[Problem]] | None:
    """Node ``name`` read from its own lines (``window``, its key on 0-based ``line``):
    the node, the values it holds, and its problems; None when the lines are not exactly
    one node of that name, or could only be read in context."""
    problems: list[Problem] = []

    def problem(message: str, at: int | None = None, node: Any = None, input: Any = None):
        from ..core.errors import Where

        problems.append(Problem(Where(file, at, node, input), message))

    try:
        root, bulk = compose("\n" * line + window)
        # the node's lines sit one level deeper in the file (under 'nodes:') than here
        too_big, count, own = expansion(root, bulk, MAX_VALUES, MAX_DEPTH - 1)
    except (yaml.YAMLError, ValueError, RecursionError):
        return None
    if too_big or count != own or not isinstance(root, yaml.MappingNode) or root.flow_style:
        return None
    if len(root.value) != 1:
        return None
    key, body = root.value[0]
    if not (isinstance(key, yaml.ScalarNode) and key.value == name and key.style in (None, "")):
        return None
    if key.start_mark.line != line:
        return None
    nd = node_def(name, line + 1, body, problem, bulk)
    if nd is None:
        return None
    return nd, count, problems


def _same_node(a: NodeDef, b: NodeDef) -> bool:
    return (a.name, a.type, a.line, a.raw, a.input_lines, a.parse_errors) == (
        b.name, b.type, b.line, b.raw, b.input_lines, b.parse_errors
    ) and (a.repeat_raw, a.simulate_raw) == (b.repeat_raw, b.simulate_raw)  # fmt: skip


def reparse(before: Document, old: str, new: str, name: str, file: str) -> Document | None:
    """``new`` read as :func:`~.yamlio.parse` reads it, knowing that ``before`` is ``old``
    read and that ``new`` differs from ``old`` within node ``name``'s lines only; None when
    that is not so, or when reading those lines alone could differ from reading the whole
    text (then read the whole text).

    ``before`` must have no problems and no aliases. The nodes the edit did not change or
    move are shared with ``before`` (a graph never changes a node in place:
    :meth:`~.model.NodeDef.moved`); its params are copies (the check sets their kinds).
    """
    if before.problems or before.top_keys is None or before.sizes[0] != before.sizes[1]:
        return None
    span = node_span(old, before.nodes, name)
    if span is None:
        return None
    start, end, line = span
    grown = len(new) - len(old)
    if end + grown < start or new[:start] != old[:start] or new[end + grown :] != old[end:]:
        return None
    was, now = old[start:end], new[start : end + grown]
    if _CONTEXTUAL.search(was) or _CONTEXTUAL.search(now):
        return None
    if len(new) * 4 > MAX_BYTES and len(new.encode()) > MAX_BYTES:
        return None
    if estimate_values(new) > 2 * MAX_VALUES:
        return None
    read_was = _window_node(was, line, name, file)
    read_now = _window_node(now, line, name, file)
    if read_was is None or read_now is None or read_now[2] or read_was[2]:
        return None
    if not _same_node(read_was[0], before.nodes[name]):
        return None  # the lines found are not the node as the whole text read it
    values = before.sizes[0] - read_was[1] + read_now[1]
    if values > MAX_VALUES:
        return None
    lines = now.count("\n") - was.count("\n")
    nodes: dict[str, NodeDef] = {}
    after = False
    for n, nd in before.nodes.items():
        if n == name:
            nodes[n], after = read_now[0], True
        else:
            nodes[n] = nd.moved(lines) if after and lines else nd  # (not changed in place)
    params = {}
    for n, p in before.params.items():
        p = copy.copy(p)
        if lines and p.line is not None and p.line > line + 1:
            p.line += lines
        params[n] = p
    output_lines = {
        n: at + lines if lines and at > line + 1 else at for n, at in before.output_lines.items()
    }
    return Document(
        description=before.description,
        params=params,
        nodes=nodes,
        outputs=dict(before.outputs),
        output_lines=output_lines,
        top_keys=before.top_keys,
        layout=dict(before.layout),
        sizes=(values, values),
    )


def recheck(before: Outline, after: Outline, name: str) -> bool:
    """Whether ``after`` has no problem, knowing that ``before`` had none (its ``types``
    those its check found) and that ``after`` is ``before`` with node ``name`` changed and
    every other node, param and output as it was (lines aside). False: not proved (run the
    whole check, which names the problems).

    What a node's check reads is its own definition, the params, the names of the nodes,
    and for each wire its target's definition and output type; only ``name`` and the nodes
    wired to it can see a change, unless ``name``'s output types changed (then False).
    """
    if before.subgraphs or after.subgraphs or list(before.nodes) != list(after.nodes):
        return False
    if list(before.params) != list(after.params) or before.outputs != after.outputs:
        return False
    nd = after.nodes.get(name)
    registry = node_types()
    spec = registry.get(nd.type) if nd is not None else None
    if nd is None or spec is None or is_graph_type(nd.type):
        return False
    if _reaches(after.nodes, nd, name):
        return False  # a cycle through the edited node
    infer_fed(after, registry)
    if param_problems(after):
        return False
    after.types.update((k, t) for k, t in before.types.items() if k[0] != name)
    for out in spec.outputs if spec.multi_output else [None]:
        key = (name, out)
        if (
            key not in before.types
            or output_type(after, Wire(name, out), registry) != (before.types[key])
        ):
            return False  # its consumers' consumers may see another type
    if any(k[0] == name and k not in after.types for k in before.types):
        return False
    expression_ports_take_text(after, nd, spec)
    if _check_node(after, nd, spec, registry):
        return False
    for other in after.nodes.values():
        if other is not nd and name in other.upstream():
            other_spec = registry.get(other.type)
            if other_spec is None or _check_node(after, other, other_spec, registry):
                return False
    return not _check_outputs(after, registry)


def _reaches(nodes: Mapping[str, NodeDef], nd: NodeDef, name: str) -> bool:
    """Whether ``name`` is upstream of ``nd``'s inputs (a cycle through it)."""
    seen: set[str] = set()
    stack = list(nd.upstream())
    while stack:
        up = stack.pop()
        if up == name:
            return True
        if up in seen or up not in nodes:
            continue
        seen.add(up)
        stack.extend(nodes[up].upstream())
    return False
