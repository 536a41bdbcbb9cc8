"""What each worker process of the embedded cluster does as it starts (a Dask preload).

The embedded cluster has one single-threaded worker per core (:func:`.cluster.connect`):
BLAS is held to one thread through the environment, but manifold3d runs its booleans on
oneTBB, built into its extension, which starts a thread per core of the process's CPU
affinity the first time it is used, and reads no environment variable. Two workers on two
cores then ran up to four threads: a lamp-shade trial took 0.29 s of CPU in 0.20 s alone,
and two workers gained only 1.5x over one. oneTBB fixes its thread count at that first use,
so it is made under an affinity of one core, and the process gets all its cores back.
"""

from __future__ import annotations

import os
from typing import Any


def dask_setup(worker: Any = None) -> None:
    """Dask's preload hook, called in the worker process before it takes any task."""
    one_thread_for_manifold()


def one_thread_for_manifold() -> bool:
    """Fix manifold3d's oneTBB at one thread in this process; whether it was done (not
    where the platform has no CPU affinity, manifold3d is missing, or one core is all)."""
    if not hasattr(os, "sched_setaffinity"):
        return False
    try:
        import manifold3d
    except ImportError:
        return False
    cores = os.sched_getaffinity(0)
    if len(cores) < 2:
        return False
    os.sched_setaffinity(0, {min(cores)})
    try:
        # a small boolean: oneTBB's first parallel work, which sizes its thread pool
        cube = manifold3d.Manifold.cube([1.0, 1.0, 1.0])
        (cube - manifold3d.Manifold.cube([0.5, 0.5, 2.0])).to_mesh()
    finally:
        os.sched_setaffinity(0, cores)
    return True
