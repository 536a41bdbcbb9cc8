"""The node registry: one decorated, typed, documented function per node type.

The registry is the single source of the YAML validation, the catalogue (``formgraph
nodes``), the JSON Schema (``formgraph schema``) and the documentation's node reference. A
node is declared by its signature: parameter names are the ports, hints their types,
defaults their defaults; the numpydoc ``Parameters`` section documents each port.
"""

from __future__ import annotations

import functools
import inspect
import math
import re
import typing
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import memory, safety
from .errors import BudgetError
from .types import PortType, Range, Variables, port_type

__all__ = ["Context", "NodeSpec", "Port", "Range", "Variables", "node", "node_types", "REQUIRED"]

DEFAULT_BUDGET = 50_000_000

# The least bytes one element of each unit a guard counts takes in the node's output
# (float64 coordinates, indices at 4 bytes at the least). A guard that does not state its
# ``nbytes`` is checked against memory with this lower bound, so it refuses only an output
# that surely cannot fit; units that count work rather than output (tests, updates,
# passes) have none.
LEAST_BYTES = {
    "points": 24,
    "vertices": 24,
    "control points": 24,
    "glyph control points": 16,
    "curve samples": 24,
    "surface samples": 24,
    "sample points": 24,
    "tool-path points": 24,
    "coordinates": 8,
    "samples": 8,
    "faces": 12,
    "triangles": 12,
    "face corners": 4,
}


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()


@dataclass(frozen=True)
class Port:
    """One input of a node type."""

    name: str
    type: PortType
    default: Any = REQUIRED
    doc: str = ""

    @property
    def required(self) -> bool:
        return self.default is REQUIRED


@dataclass(frozen=True)
class NodeSpec:
    """A registered node type: its function, ports, outputs and documentation."""

    name: str
    func: Callable[..., Any]
    version: int
    inputs: dict[str, Port]
    outputs: dict[str, PortType]
    summary: str
    doc: str
    wants_context: bool
    multi_output: bool = False
    output_class: Any = None  # the NamedTuple of a node with several outputs
    # an optional dependency the node needs: a callable that says, in a sentence, what is
    # missing and how to install it (None when it is there); asked by the check
    requires: Callable[[], str | None] | None = None

    def missing(self) -> str | None:
        """What this node needs and is not installed (a sentence), or None."""
        return self.requires() if self.requires is not None else None

    @property
    def family(self) -> str:
        return self.name.split(".", 1)[0]

    @functools.cached_property
    def is_export(self) -> bool:
        return any(p.type.is_output_path for p in self.inputs.values())

    @functools.cached_property
    def input_paths(self) -> tuple[str, ...]:
        """The ports that name files the node reads (their bytes key the node)."""
        return tuple(n for n, p in self.inputs.items() if p.type.is_input_path)

    def output_type(self, output: str | None) -> PortType:
        if output is None:
            return next(iter(self.outputs.values()))
        return self.outputs[output]


class _Registry(dict):
    """The registered node types: a dict that counts its changes, so :func:`node_types`
    knows in one comparison whether its sorted copy is still current (a test may replace
    an entry in place, e.g. with ``monkeypatch.setitem``)."""

    changes = 0

    def _changed(self) -> None:
        self.changes += 1

    def __setitem__(self, key: str, value: NodeSpec) -> None:
        super().__setitem__(key, value)
        self._changed()

    def __delitem__(self, key: str) -> None:
        super().__delitem__(key)
        self._changed()

    def pop(self, *args: Any) -> Any:
        self._changed()
        return super().pop(*args)

    def popitem(self) -> tuple[str, NodeSpec]:
        self._changed()
        return super().popitem()

    def setdefault(self, key: str, default: Any = None) -> Any:
        self._changed()
        return super().setdefault(key, default)

    def update(self, *args: Any, **kwargs: Any) -> None:
        super().update(*args, **kwargs)
        self._changed()

    def clear(self) -> None:
        super().clear()
        self._changed()

    def __ior__(self, other: Any) -> _Registry:
        self.update(other)
        return self


_REGISTRY: _Registry = _Registry()
_SORTED: dict[str, NodeSpec] = {}  # _REGISTRY in name order, rebuilt after a change
_SORTED_AT = [-1]  # the _REGISTRY.changes that _SORTED was built at


def node(
    name: str, *, version: int = 1, requires: Callable[[], str | None] | None = None
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register a function as the node type ``name`` (e.g. ``"points.circle"``).

    ``version`` is part of every cache key: bump it when the node's results change.
    ``requires`` names an optional dependency: a callable giving None when it is
    installed, else the sentence the check reports (what is missing, how to install it),
    so a graph using the node fails at ``formgraph check``, located, not at run time.
    """
    if not re.fullmatch(r"[a-z][a-z0-9_]*\.[a-z0-9][a-z0-9_]*", name):  # export.3mf
        raise ValueError(f"node type names are 'family.name' in lower case, got {name!r}")

    def register(func: Callable[..., Any]) -> Callable[..., Any]:
        if name in _REGISTRY and _REGISTRY[name].func.__qualname__ != func.__qualname__:
            raise ValueError(f"node type {name!r} is registered twice")
        _REGISTRY[name] = _spec_from_function(name, version, func, requires)
        return func

    return register


def node_types() -> dict[str, NodeSpec]:
    """Every registered node type, by name (importing the node families first)."""
    import formgraph.nodes  # noqa: F401  (registers the families on import)

    # Sorted once per change of the registry (every run asks; a sweep, once per variant and
    # again in the worker): one comparison of the change count, not a walk of the entries.
    if _SORTED_AT[0] != _REGISTRY.changes:
        _SORTED.clear()
        _SORTED.update(sorted(_REGISTRY.items()))
        _SORTED_AT[0] = _REGISTRY.changes
    return dict(_SORTED)


def _spec_from_function(
    name: str,
    version: int,
    func: Callable[..., Any],
    requires: Callable[[], str | None] | None = None,
) -> NodeSpec:
    hints = typing.get_type_hints(func, include_extras=True)
    sig = inspect.signature(func)
    docs = parse_param_docs(func.__doc__ or "")
    inputs: dict[str, Port] = {}
    wants_context = False
    for pname, p in sig.parameters.items():
        hint = hints.get(pname)
        if hint is Context:
            wants_context = True
            continue
        if hint is None:
            raise TypeError(f"node {name!r}: port {pname!r} has no type hint")
        default = REQUIRED if p.default is inspect.Parameter.empty else p.default
        inputs[pname] = Port(pname, port_type(hint), default, docs.get(pname, ""))
    ret = hints.get("return")
    if ret is None:
        raise TypeError(f"node {name!r} has no return type hint")
    multi = isinstance(ret, type) and issubclass(ret, tuple) and hasattr(ret, "_fields")
    if multi:
        outputs = {f: port_type(t) for f, t in typing.get_type_hints(ret).items()}
    else:
        outputs = {"out": port_type(ret)}
    doc = inspect.cleandoc(func.__doc__ or "")
    summary = doc.split("\n\n", 1)[0].replace("\n", " ").strip()
    return NodeSpec(
        name,
        func,
        version,
        inputs,
        outputs,
        summary,
        doc,
        wants_context,
        multi,
        ret if multi else None,
        requires,
    )


def parse_param_docs(doc: str) -> dict[str, str]:
    """Port descriptions from a numpydoc ``Parameters`` section."""
    lines = inspect.cleandoc(doc).splitlines()
    out: dict[str, str] = {}
    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == "Parameters")
    except StopIteration:
        return out
    current: str | None = None
    for ln in lines[start + 2 :]:
        if ln.strip() and not ln.startswith(" ") and not re.match(r"^[\w, ]+ ?:", ln):
            break  # next section title
        if re.match(r"^---", ln.strip()):
            break
        m = re.match(r"^([\w, ]+?)\s*:", ln)
        if m and not ln.startswith(" "):
            names = [n.strip() for n in m.group(1).split(",")]
            current = ",".join(names)
            for n in names:
                out[n] = ""
        elif current and ln.strip():
            for n in current.split(","):
                out[n] = (out[n] + " " + ln.strip()).strip()
        elif not ln.strip() and current is None:
            continue
    # a section header that follows (e.g. 'Returns' then '-----') ends the list
    return {k: v for k, v in out.items() if k not in ("Returns", "Raises", "Example", "Examples")}


def _count(elements: int | float) -> str:
    """A count for a message: exact while readable, then its order of magnitude."""
    if elements < 1e15:
        return f"{int(elements):,}"
    if isinstance(elements, float):
        return f"{elements:.3g}" if elements != float("inf") else "infinitely many"
    return f"about 10^{int(math.log10(elements))}"  # exact for ints of any size


RUN_FACTOR = 4
"""A run may hold this many budgets of elements at once (what its nodes made so far and the
one about to be made): each node alone stays under the budget, the run under four."""


class Estimate(Exception):
    """Raised by :meth:`Context.guard` of a probing context: what the node would make."""

    def __init__(self, elements: int | float):
        super().__init__(elements)
        self.elements = elements


@dataclass
class RunTally:
    """The elements a run's nodes were allowed so far, against :data:`RUN_FACTOR` budgets,
    and the bytes of the outputs it holds (for the message of a node refused for memory)."""

    budget: int
    total: float = 0
    held: int = 0  # bytes of the outputs the run has made or fetched so far

    @property
    def limit(self) -> int:
        return RUN_FACTOR * self.budget

    def charge(self, elements: int | float, what: str) -> None:
        if self.total + elements > self.limit:
            raise BudgetError(
                f"would make {_count(elements)} {what} while the run already holds about "
                f"{_count(self.total)} elements from earlier nodes: together over "
                f"{RUN_FACTOR} x the budget of {self.budget:,} ({self.limit:,}), what one run "
                "may hold at once; raise it with budget= or --budget if you mean it"
            )
        self.total += elements


@dataclass
class Context:
    """What a running node may use besides its inputs: budget, output directory, warnings.

    Passed to node functions that declare a keyword-only ``ctx: Context`` parameter.
    """

    node: str
    out_dir: Path
    budget: int = DEFAULT_BUDGET
    warnings: list[str] = field(default_factory=list)
    written: list[Path] = field(default_factory=list)
    inputs: Callable[[str], tuple[Path, bytes]] | None = None  # input path -> (file, bytes)
    tally: RunTally | None = None  # the run's total (None: this node alone)
    probe: bool = False  # only asking what the node would make: guard raises Estimate
    start: Any = None  # a step of a simulation: the state it started from (its ``from``)

    def guard(
        self,
        elements: int | float,
        what: str = "elements",
        *,
        nbytes: int | float | None = None,
        port: str | None = None,
    ) -> None:
        """Refuse, before allocating, an output of more than the element budget, one that
        would bring the run past :data:`RUN_FACTOR` budgets in all, or (given ``nbytes``,
        the bytes the output will take) one that would not fit in the memory the process
        has left with its transient copy (:mod:`formgraph.core.memory`). ``port`` names
        the input the refusal is located on (the one that asks for so much)."""
        if self.probe:
            raise Estimate(elements)
        try:
            if self.tally is not None and elements <= self.budget:
                self.tally.charge(elements, what)
            if elements > self.budget:
                count = _count(elements)
                raise BudgetError(
                    f"would make {count} {what}, over the budget of "
                    f"{self.budget:,} (raise it with budget= or --budget if you mean it)"
                )
            if nbytes is not None:
                self._fits(elements, what, nbytes)
            elif what in LEAST_BYTES:
                self._fits(elements, what, LEAST_BYTES[what] * elements, least=True)
        except BudgetError as exc:
            exc.port = port
            raise

    def _fits(
        self, elements: int | float, what: str, nbytes: int | float, least: bool = False
    ) -> None:
        need = memory.PEAK_FACTOR * nbytes
        if need < memory.UNCHECKED:
            return
        room = memory.room()
        if room is None or need <= room.bytes:
            return
        held = self.tally.held if self.tally is not None else 0
        also = f"; this run holds {memory.fmt_bytes(held)} of earlier outputs" if held else ""
        raise BudgetError(
            f"would make {_count(elements)} {what}, {'at least ' if least else ''}"
            f"{memory.fmt_bytes(nbytes)} (about {memory.fmt_bytes(need)} while it is made), "
            f"but the process has "
            f"{room.describe()}{also}: refused before allocating"
        )

    def write(self, path: str, data: bytes | Iterable[bytes]) -> Path:
        """Write ``data`` (bytes-like, or an iterable of bytes-like pieces written as they
        come) atomically to ``path`` inside the output directory."""
        target = safety.write_atomic(self.out_dir, path, data)
        self.written.append(target)
        return target

    def read(self, path: str) -> tuple[Path, bytes]:
        """The file an input path names and its bytes: the very bytes hashed into this
        node's cache key, read once (regular files only, capped; see
        :func:`formgraph.core.safety.read_regular`)."""
        if self.inputs is None:
            raise RuntimeError("this context reads no input files")
        return self.inputs(path)

    def warn(self, message: str) -> None:
        """Record a warning in this node's stats (shown by the CLI)."""
        self.warnings.append(message)
