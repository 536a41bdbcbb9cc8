"""Stub node types for the sweep tests, run by Dask worker processes.

Worker processes do not share the test's memory, so these nodes leave their run record in
a file (one line per call, appended). Like ``stubs``, they register under ``stub`` and only
when the tests import this module (the workers import it by name, as sweeps do for any node
type defined outside formgraph).
"""

from __future__ import annotations

import os
import time
from typing import NamedTuple

import numpy as np

from formgraph.core.registry import node
from formgraph.geometry import Curve, Mesh


def calls(log: str | os.PathLike[str]) -> list[str]:
    """The labels of every call recorded in ``log``, in order."""
    try:
        with open(log, encoding="utf-8") as fh:
            return fh.read().split()
    except FileNotFoundError:
        return []


@node("stub.logged", version=1)
def logged(
    x: float, log: str, label: str = "", seconds: float = 0.0, hold: str = "", after: int = 0
) -> float:
    """x, after recording ``label:x`` in the file ``log`` (and sleeping ``seconds``); once
    ``log`` has ``after`` calls, each waits while the file ``hold`` exists (a test's latch:
    the sweep stands still where the test wants it, however slow the machine).

    Parameters
    ----------
    x : float
        The number.
    log : str
        The run record file.
    label : str
        What to record.
    seconds : float
        How long to take.
    hold : str
        A file to wait on while it exists ("": none).
    after : int
        Calls recorded in ``log`` before ``hold`` is waited on.
    """
    time.sleep(seconds)
    end = time.monotonic() + 600  # a latch never removed is a test's bug: not forever
    while hold and os.path.exists(hold) and len(calls(log)) >= after and time.monotonic() < end:
        time.sleep(0.02)
    fd = os.open(log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        os.write(fd, f"{label}:{x:g}\n".encode())
    finally:
        os.close(fd)
    return x


@node("stub.fail_at", version=1)
def fail_at(x: float, bad: float) -> float:
    """x, or a ValueError when x equals ``bad``.

    Parameters
    ----------
    x : float
        The number.
    bad : float
        The value that fails.
    """
    if x == bad:
        raise ValueError(f"{x:g} is the bad value\nsecond line of the message")
    return x


@node("stub.die_at", version=1)
def die_at(x: float, bad: float) -> float:
    """x, or the process ends at once (as an out-of-memory kill ends a worker) when x equals
    ``bad``.

    Parameters
    ----------
    x : float
        The number.
    bad : float
        The value that kills.
    """
    if x == bad:
        os._exit(1)
    return x


class CurveStats(NamedTuple):
    length: float
    closed: bool
    samples: int
    curve: Curve


@node("stub.curve_stats", version=1)
def curve_stats(curve: Curve, samples: int = 200) -> CurveStats:
    """The length of a curve's polyline through ``samples`` points, and more.

    Parameters
    ----------
    curve : Curve
        The curve.
    samples : int
        Points along it.
    """
    pts = np.asarray(curve.sample(samples))
    length = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
    return CurveStats(length, bool(curve.closed), samples, curve)


class MeshStats(NamedTuple):
    vertices: int
    faces: int
    extent: float


@node("stub.mesh_stats", version=1)
def mesh_stats(mesh: Mesh) -> MeshStats:
    """Counts and the bounding box diagonal of a mesh.

    Parameters
    ----------
    mesh : Mesh
        The mesh.
    """
    v = np.asarray(mesh.vertices)
    return MeshStats(mesh.n_vertices, mesh.n_faces, float(np.linalg.norm(v.max(0) - v.min(0))))
