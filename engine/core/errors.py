"""The errors formgraph raises: one base, two meaningful kinds.

``GraphError`` is a problem with the graph itself (found before anything runs: unknown types,
bad wires, type mismatches, cycles, bad params); ``NodeError`` is a node that failed while
running, with the original exception chained. Both read as sentences that name the file, the
line, the node and the input.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Where:
    """Where in a graph file a problem is: any part may be unknown."""

    file: str | None = None
    line: int | None = None
    node: str | None = None
    input: str | None = None

    def prefix(self) -> str:
        loc = self.file or "<graph>"
        if self.line is not None:
            loc += f":{self.line}"
        parts = [loc]
        if self.node is not None:
            parts.append(f"node '{self.node}'")
        if self.input is not None:
            parts.append(f"input '{self.input}'")
        return ": ".join(parts) if len(parts) == 1 else parts[0] + ": " + ", ".join(parts[1:])


@dataclass(frozen=True)
class Problem:
    """One problem found while checking a graph."""

    where: Where
    message: str

    def __str__(self) -> str:
        w = self.where
        if w.file is None and w.line is None and w.node is None and w.input is None:
            return self.message  # nothing to locate: the message says it all
        return f"{w.prefix()}: {self.message}"


class FormgraphError(Exception):
    """Base of every formgraph error."""


class GraphError(FormgraphError):
    """A graph that cannot run: every problem found, each with file, line, node and input."""

    def __init__(self, problems: list[Problem] | Problem | str):
        if isinstance(problems, str):
            problems = [Problem(Where(), problems)]
        elif isinstance(problems, Problem):
            problems = [problems]
        self.problems: list[Problem] = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class ParamError(GraphError):
    """A graph parameter that is unknown or out of its declared range."""


class CycleError(GraphError):
    """Wires that loop back on themselves."""


class BudgetError(GraphError):
    """A node whose output would exceed the element budget or the memory left (refused
    before allocating); ``port``, when known, is the input that asks for so much."""

    port: str | None = None


class PathError(GraphError):
    """A path that may not be written or read (it leaves its folder, names a folder, ...).

    ``path`` is the refused path when the path itself is what is wrong (not the folder it
    is in): a run then locates the error on the node's path input.
    """

    path: str | None = None

    @classmethod
    def of(cls, path: str, message: str) -> PathError:
        """The error refusing ``path`` itself."""
        exc = cls(message)
        exc.path = path
        return exc


class ExpressionError(GraphError):
    """An expression that is not in the whitelisted language."""


class NodeError(FormgraphError):
    """A node that failed while running; ``__cause__`` is the original exception."""

    def __init__(self, where: Where, node_type: str, message: str):
        self.where = where
        self.node_type = node_type
        super().__init__(f"{where.prefix()} ({node_type}): {message}")


class FormgraphWarning(UserWarning):
    """A node's warning (a hole in a mesh, a value clamped), also kept in ``g.stats``.

    Emitted through :mod:`warnings`, so ``warnings.simplefilter("error", FormgraphWarning)``
    turns them into errors and ``pytest.warns`` catches them.
    """


class InputError(ValueError):
    """Raised by a node function to say which of its inputs holds a bad value."""

    def __init__(self, port: str, message: str):
        self.port = port
        super().__init__(message)

    @classmethod
    def call(cls, port: str, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """``fn(*args, **kwargs)``, a kernel's ValueError made an InputError on ``port``:
        the node input the kernel's complaint is about (an InputError from inside already
        names its own input and passes unchanged)."""
        try:
            return fn(*args, **kwargs)
        except InputError:
            raise
        except ValueError as exc:
            raise cls(port, str(exc)) from None


class UsageError(Exception):
    """A command line that does not make sense (exit code 2); not a problem of a graph."""
