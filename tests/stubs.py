"""Stub node types for executor tests, with a run record of every call.

They register under the family ``stub`` when this module is imported (only by the tests),
so the shipped catalogue never contains them.
"""

from __future__ import annotations

from typing import Annotated, NamedTuple

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, Range, node
from formgraph.core.types import OutputPath
from formgraph.geometry import Points

CALLS: list[str] = []


def did_run(name: str) -> bool:
    return name in CALLS


@node("stub.value", version=1)
def value(x: float = 0.0, label: str = "") -> float:
    """A number passed through.

    Parameters
    ----------
    x : float
        The number.
    label : str
        Only there to make distinct nodes.
    """
    CALLS.append(f"value:{label}")
    return x


@node("stub.add", version=1)
def add(a: float, b: float = 0.0, label: str = "") -> float:
    """a + b.

    Parameters
    ----------
    a, b : float
        The terms.
    label : str
        Only there to make distinct nodes.
    """
    CALLS.append(f"add:{label}")
    return a + b


@node("stub.floor", version=1)
def floor(a: float, label: str = "") -> float:
    """The floor of a (many inputs give one output: for early cutoff).

    Parameters
    ----------
    a : float
        The number.
    label : str
        Only there to make distinct nodes.
    """
    CALLS.append(f"floor:{label}")
    return float(np.floor(a))


@node("stub.sum", version=1)
def total(items: list[float], label: str = "") -> float:
    """The sum of a list.

    Parameters
    ----------
    items : list[float]
        The numbers.
    label : str
        Only there to make distinct nodes.
    """
    CALLS.append(f"sum:{label}")
    return float(sum(items))


@node("stub.points", version=1)
def points(n: Annotated[int, Range(min=0)], scale: float = 1.0, *, ctx: Context) -> Points:
    """n points on the x axis.

    Parameters
    ----------
    n : int
        Count.
    scale : float
        Spacing.
    """
    ctx.guard(n, "points")
    CALLS.append("points")
    x = np.arange(n, dtype=float) * scale
    return Points(np.stack([x, np.zeros(n), np.zeros(n)], axis=-1))


@node("stub.fail", version=1)
def fail(x: float, how: str = "value") -> float:
    """Fails on purpose.

    Parameters
    ----------
    x : float
        Ignored.
    how : str
        'value' (ValueError), 'input' (InputError on x) or 'bug' (IndexError).
    """
    if how == "input":
        raise InputError("x", "x must be prime")
    if how == "bug":
        return [][1]
    raise ValueError("this node always fails")


@node("stub.write", version=1)
def write(text: str, path: OutputPath, *, ctx: Context) -> str:
    """Writes text to a file in the output directory.

    Parameters
    ----------
    text : str
        The content.
    path : OutputPath
        Where, relative to the output directory.
    """
    CALLS.append("write")
    return str(ctx.write(path, text.encode()))


@node("stub.pair", version=1)
def pair(a: float, b: float) -> list[float]:
    """[a, b].

    Parameters
    ----------
    a, b : float
        The two numbers.
    """
    CALLS.append("pair")
    return [a, b]


class Split(NamedTuple):
    lo: float
    hi: float


@node("stub.split", version=1)
def split(x: float) -> Split:
    """x - 1 and x + 1 (a node with two named outputs).

    Parameters
    ----------
    x : float
        The number.
    """
    return Split(x - 1.0, x + 1.0)
