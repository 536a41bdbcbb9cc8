"""Composing graph text: libyaml, YAML 1.2 numbers, and a cost bounded by what is accepted.

- Plain scalars are resolved as YAML 1.2's core schema does, not as PyYAML's YAML 1.1:
  ``1e-3`` and ``1.0e308`` are numbers, ``1:30`` (1.1's base 60) and ``yes``/``on`` are
  text, ``012`` is twelve, and a date is text (:class:`_Resolver`, :class:`Constructor`).
- Before anything is built, :func:`estimate_values` counts the text's structure (a few
  milliseconds for the largest file allowed), and :func:`expansion_problem` counts the
  composed tree exactly, aliases expanded, naming the real reason for a refusal.
- Plain data (strings, numbers, lists, mappings) is built by :func:`construct` without the
  generic constructor's bookkeeping; a long array of numbers is read by the json module
  before composing (:func:`lift_number_arrays`), which is where a big file's time goes.
  Anything else (tags, merge keys) goes through PyYAML's safe constructor.
"""

from __future__ import annotations

import json
import re
from typing import Any

import yaml

_INT = re.compile(r"[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+")
_FLOAT = re.compile(
    r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?|[-+]?\.(?:inf|Inf|INF)"
    r"|\.(?:nan|NaN|NAN)"
)


_PLAIN = re.compile(
    rf"(?P<int>{_INT.pattern})|(?P<float>{_FLOAT.pattern})"
    r"|(?P<bool>true|True|TRUE|false|False|FALSE)|(?P<null>~|null|Null|NULL|)"
    r"|(?P<merge><<)"  # not YAML 1.2, but anchors with merge keys are common in graphs
)
_TAGS = {name: f"tag:yaml.org,2002:{name}" for name in ("int", "float", "bool", "null", "merge")}


class _Resolver(yaml.resolver.Resolver):
    """YAML 1.2 core schema tags for plain scalars (PyYAML alone speaks YAML 1.1).

    One regular expression decides a plain scalar's tag (PyYAML's table of resolvers per
    first character costs several times more per scalar).
    """

    def resolve(self, kind: Any, value: Any, implicit: Any) -> str:
        if kind is yaml.ScalarNode and implicit[0]:
            m = _PLAIN.fullmatch(value)
            return _TAGS[m.lastgroup] if m else self.DEFAULT_SCALAR_TAG
        return super().resolve(kind, value, implicit)


try:
    from yaml.cyaml import CParser as _CParser  # libyaml: 20 times faster than pure Python
except ImportError:  # pragma: no cover - PyYAML without libyaml
    _CParser = None

if _CParser is not None:

    class Loader(_CParser, yaml.constructor.SafeConstructor, _Resolver):
        """Composing with libyaml, YAML 1.2 numbers."""

        def __init__(self, stream: str):
            _CParser.__init__(self, stream)
            yaml.constructor.SafeConstructor.__init__(self)
            _Resolver.__init__(self)

else:  # pragma: no cover - PyYAML without libyaml

    class Loader(_Resolver, yaml.SafeLoader):  # type: ignore[no-redef]
        """Composing in pure Python, YAML 1.2 numbers."""


class Constructor(yaml.constructor.SafeConstructor):
    """The safe constructor with YAML 1.2 numbers (also for explicit ``!!int``/``!!float``)."""

    def construct_yaml_int(self, node: yaml.Node) -> int:
        text = str(self.construct_scalar(node))
        if not _INT.fullmatch(text):
            raise yaml.constructor.ConstructorError(
                None, None, f"{text!r} is not an integer", node.start_mark
            )
        try:
            if text.startswith(("0o", "0x")):
                return int(text[2:], 8 if text[1] == "o" else 16)
            return int(text)
        except ValueError:  # Python refuses to read more than 4300 digits
            raise yaml.constructor.ConstructorError(
                None, None, f"an integer of {len(text)} digits is too long", node.start_mark
            ) from None

    def construct_yaml_float(self, node: yaml.Node) -> float:
        text = str(self.construct_scalar(node))
        if not (_FLOAT.fullmatch(text) or _INT.fullmatch(text)):
            raise yaml.constructor.ConstructorError(
                None, None, f"{text!r} is not a number", node.start_mark
            )
        if text.lstrip("+-").lower() == ".inf":
            return float("-inf") if text.startswith("-") else float("inf")
        if text.lower() == ".nan":
            return float("nan")
        if text.startswith(("0o", "0x")):
            return float(self.construct_yaml_int(node))
        return float(text)


Constructor.add_constructor("tag:yaml.org,2002:int", Constructor.construct_yaml_int)
Constructor.add_constructor("tag:yaml.org,2002:float", Constructor.construct_yaml_float)


def load_value(text: str) -> Any:
    """One YAML value read as a graph file reads it (YAML 1.2 numbers), e.g. for ``--set``.

    Raises
    ------
    yaml.YAMLError
        For text that is not YAML, or too big or deep to be a value.
    """
    node = yaml.compose(text, Loader=Loader)
    too_big = expansion_problem(node, Bulk(), 100_000, 64)
    if too_big:
        raise yaml.YAMLError(too_big)
    return None if node is None else construct(node)


def estimate_values(text: str) -> int:
    """About how many values the text holds, counted on its characters (a refusal only
    when it is twice the limit; the exact count comes after composing).

    Nearly every value is introduced by a line break, a ``[``, ``{``, ``,`` or ``: ``, and
    each collection also closes. Counting those costs a few milliseconds for the largest
    file allowed, while building it could take minutes.
    """
    return 1 + sum(text.count(c) for c in ("\n", "[", "{", ",", ": ", "]", "}"))


# ------------------------------------------------------------------ long arrays of numbers

BULK_CHARS = 4096  # arrays shorter than this are left to the YAML parser
_MARK = "\ufdd0"  # a Unicode noncharacter: printable in YAML, never in a real graph
# a run of the characters a number array is made of, from a '[': greedy with nothing after
# it, so it never backtracks (linear in the text); trimmed to its last ']' below
_ARRAY = re.compile(r"\[[0-9eE.,+\-\s\[\]]*")
_ARRAY_DEPTH = 4  # [[x, y, z], ...] and grids of them


class Bulk(dict):
    """Placeholder text -> (the array it stands for, how many values it holds, its depth)."""


def lift_number_arrays(text: str) -> tuple[str, Bulk]:
    """Long flow sequences of plain numbers read by the json module, each replaced in the
    text by a placeholder scalar plus the line breaks it spanned (so every line number
    stays). A span that is not exactly JSON (``012``, ``.5``, ``+1``) is left to YAML.

    The lift is only an acceleration: :func:`expansion_problem` checks afterwards that each
    placeholder came back as a whole plain scalar and nowhere else (not in a comment or a
    string), and the caller composes the original text again when one did not.
    """
    bulk = Bulk()
    if len(text) < BULK_CHARS or _MARK in text:  # the text's own noncharacters stay its own
        return text, bulk
    pieces: list[str] = []
    last = 0
    for m in _ARRAY.finditer(text):
        span = m.group()
        if len(span) < BULK_CHARS:
            continue
        span = span[: span.rfind("]") + 1]
        if len(span) < BULK_CHARS:
            continue
        if any(t.startswith("!") for t in text[max(0, m.start() - 200) : m.start()].split()[-2:]):
            continue  # a tag applies to the sequence, not to a placeholder
        depth = _bracket_depth(span)
        if depth is None or depth > _ARRAY_DEPTH:
            continue
        try:
            value = json.loads(span)
        except (ValueError, RecursionError):
            continue
        mark = f"{_MARK}{len(bulk)}{_MARK}"
        bulk[mark] = (value, _count(value), depth)
        pieces += [text[last : m.start()], mark, "\n" * span.count("\n")]
        last = m.start() + len(span)
    if not bulk:
        return text, bulk
    pieces.append(text[last:])
    return "".join(pieces), bulk


def _bracket_depth(span: str) -> int | None:
    depth = deepest = 0
    for c in re.findall(r"[\[\]]", span):
        depth += 1 if c == "[" else -1
        if depth < 0:
            return None
        deepest = max(deepest, depth)
    return deepest if depth == 0 else None


def _count(value: list[Any]) -> int:
    """Values in nested lists (each list and each number), without recursion."""
    count, stack = 0, [value]
    while stack:
        items = stack.pop()
        count += 1 + len(items)
        stack.extend(v for v in items if isinstance(v, list))
        count -= sum(1 for v in items if isinstance(v, list))  # counted when popped
    return count


def compose(text: str) -> tuple[yaml.Node | None, Bulk]:
    """The node tree of ``text`` (long number arrays lifted out, see :func:`lift_number_arrays`).

    Raises
    ------
    yaml.YAMLError
        For text that is not YAML.
    """
    lifted, bulk = lift_number_arrays(text)
    return yaml.compose(lifted, Loader=Loader), bulk


def expansion_problem(
    root: yaml.Node | None, bulk: Bulk, max_values: int, max_depth: int
) -> str | None:
    """Why the composed tree is too big to read (an alias bomb, absurd nesting), or None.

    Walks the tree without recursion, counting every node as often as aliases repeat it
    (a lifted array as the values it holds).

    Raises
    ------
    ValueError
        When a placeholder of ``bulk`` is not exactly one whole plain scalar: the text must
        be composed again without lifting.
    """
    return expansion(root, bulk, max_values, max_depth)[0]


def expansion(
    root: yaml.Node | None, bulk: Bulk, max_values: int, max_depth: int
) -> tuple[str | None, int, int]:
    """:func:`expansion_problem`, and the values counted: with aliases expanded, and as
    written (equal when the text has no alias; both partial after a problem)."""
    count = 0  # values, aliases expanded
    own = 0  # values written in the text
    distinct: set[int] = set()
    found: set[str] = set()
    stack: list[tuple[yaml.Node, int, bool]] = [] if root is None else [(root, 0, False)]
    while stack:
        node, depth, is_key = stack.pop()
        weight, inner = 1, 0
        if bulk and isinstance(node, yaml.ScalarNode) and _MARK in node.value:
            # a whole plain value ("" is libyaml's plain style), never a key
            if node.value not in bulk or node.style not in (None, "") or is_key:
                raise ValueError("a placeholder inside other text")
            found.add(node.value)
            _, weight, inner = bulk[node.value]
        count += weight
        if id(node) not in distinct:
            distinct.add(id(node))
            own += weight
        if count > max_values and own > max_values:
            return (
                f"the file holds more than {max_values:,} values (numbers, strings, lists and "
                f"mappings); a graph this large is better built in Python",
                count,
                own,
            )
        # only aliases make the tree larger than the text
        if count > max_values or (count > 100_000 and count > 4 * own):
            return (
                f"the YAML's aliases expand to more than {min(count, max_values):,} values "
                f"(aliases of aliases?); refusing to read it",
                count,
                own,
            )
        if depth + inner > max_depth:  # a lifted array's own levels count too
            return f"the YAML is nested too deeply (more than {max_depth} levels)", count, own
        if isinstance(node, yaml.SequenceNode):
            stack.extend((v, depth + 1, False) for v in node.value)
        elif isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                stack.append((k, depth + 1, True))
                stack.append((v, depth + 1, False))
    if found != set(bulk):
        raise ValueError("a placeholder outside the values (in a comment?)")
    return None, count, own


# ------------------------------------------------------------------------- construction


_NO_BULK = Bulk()


def construct(node: yaml.Node, bulk: Bulk | None = None) -> Any:
    """The Python value of a composed node (plain data fast, anything else safely).

    Raises
    ------
    yaml.YAMLError, ValueError, TypeError, ...
        From the safe constructor, for values it cannot read.
    """
    bulk = _NO_BULK if bulk is None else bulk
    try:
        return _build(node, {}, bulk)
    except _Slow:  # tags, merge keys, complex keys: the full safe constructor
        value = Constructor().construct_document(node)
        return _put_back(value, bulk) if bulk else value


def _put_back(value: Any, bulk: Bulk) -> Any:
    """``value`` with each placeholder string replaced by its array (nesting is bounded)."""
    if isinstance(value, str):
        return bulk[value][0] if value in bulk else value
    if isinstance(value, list):
        return [_put_back(v, bulk) for v in value]
    if isinstance(value, dict):
        return {k: _put_back(v, bulk) for k, v in value.items()}
    return value


class _Slow(Exception):
    """A value the fast builder leaves to the safe constructor."""


_DECIMAL = re.compile(r"[-+]?[0-9]{1,4000}")
_DECIMAL_FLOAT = re.compile(r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?")
_STR, _INT_TAG, _FLOAT_TAG = (f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float"))
_SEQ, _MAP = "tag:yaml.org,2002:seq", "tag:yaml.org,2002:map"
_BOOLS = {"true": True, "True": True, "TRUE": True, "false": False, "False": False, "FALSE": False}


def _build(node: yaml.Node, memo: dict[int, Any], bulk: Any) -> Any:
    """The Python value of plain YAML data (what graph files hold), several times faster
    than the generic constructor; raises :class:`_Slow` for anything else. Recursion is
    bounded by the nesting check that runs first."""
    if id(node) in memo:  # an alias: the same value, as the safe constructor gives
        return memo[id(node)]
    tag = node.tag
    if isinstance(node, yaml.ScalarNode):
        text = node.value
        if tag == _STR:
            return bulk[text][0] if text in bulk else text
        if tag == _FLOAT_TAG and _DECIMAL_FLOAT.fullmatch(text):
            return float(text)
        if tag == _INT_TAG and _DECIMAL.fullmatch(text):
            return int(text)
        if tag == "tag:yaml.org,2002:null" and text in ("", "~", "null", "Null", "NULL"):
            return None
        if tag == "tag:yaml.org,2002:bool" and text in _BOOLS:
            return _BOOLS[text]
        raise _Slow
    if tag == _SEQ and isinstance(node, yaml.SequenceNode):
        out: Any = [_build(v, memo, bulk) for v in node.value]
    elif tag == _MAP and isinstance(node, yaml.MappingNode):
        out = {}
        for k, v in node.value:
            if not isinstance(k, yaml.ScalarNode) or k.tag == "tag:yaml.org,2002:merge":
                raise _Slow
            out[_build(k, memo, bulk)] = _build(v, memo, bulk)
    else:
        raise _Slow
    memo[id(node)] = out
    return out
