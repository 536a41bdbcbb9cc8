"""The embedded cluster's workers run manifold3d's booleans on one thread: oneTBB, inside
manifold3d, would start a thread per core in each worker (two workers on two cores ran four
threads, and gained 1.5x over one worker instead of nearly 2x)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.skipif(
    not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2,
    reason="needs CPU affinity and two cores",
)

THREADS = textwrap.dedent(
    """
    import os, sys
    import manifold3d
    from formgraph.sweeps.workerinit import one_thread_for_manifold

    cores = os.sched_getaffinity(0)
    done = one_thread_for_manifold() if sys.argv[1] == "init" else None
    before = len(os.listdir("/proc/self/task"))
    a = manifold3d.Manifold.sphere(1.0, 256)
    for i in range(20):  # enough parallel work that every pool thread is started
        a = a - manifold3d.Manifold.cube([0.3, 0.3, 3.0]).translate([0.1 * i - 1, 0, -1.5])
    a.to_mesh()
    print(done, len(os.listdir("/proc/self/task")) - before, os.sched_getaffinity(0) == cores)
    """
)


def _threads_added(mode: str) -> list[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    r = subprocess.run(
        [sys.executable, "-c", THREADS, mode], capture_output=True, text=True, timeout=120, env=env
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout.split()


def test_a_boolean_adds_no_thread_after_the_init_and_the_cores_are_given_back():
    assert _threads_added("init") == ["True", "0", "True"]


def test_without_it_manifold3d_starts_a_thread_pool():
    # the reference: what the init prevents (if manifold3d ever stops threading, this
    # fails, and the init can go)
    done, added, _ = _threads_added("plain")
    assert done == "None" and int(added) >= 1


@pytest.mark.skipif(
    hasattr(os, "sched_getaffinity") and len(os.sched_getaffinity(0)) != 2,
    reason="the preload applies when the workers fill the cores: two here",
)
def test_the_embedded_cluster_preloads_it(tmp_path):
    import formgraph as fg
    from formgraph.sweeps import cluster

    with cluster.connect(None, workers=2) as client:  # two workers on two cores
        workers = list(client.scheduler_info()["workers"])
        # each worker's task thread started (Dask starts it at the worker's first task)
        client.gather([client.submit(abs, -1, workers=[w], pure=False) for w in workers])
        seen = client.run(lambda: len(os.listdir("/proc/self/task")))
        g = fg.Graph()
        g.add_param("r", 1.0)
        g.add("a", "mesh.sphere", radius="=r")
        g.add("b", "mesh.box", size=[0.5, 0.5, 3.0])
        g.add("c", "mesh.boolean", a="@a", b="@b", operation="difference")
        g.add("m", "mesh.measure", mesh="@c")
        s = fg.sweep(g, {"r": "0.8:1.2:8"}, ["m"], client=client, cache_dir=None)
        after = client.run(lambda: len(os.listdir("/proc/self/task")))
    assert all(r["status"] == "ok" for r in s.rows)
    assert after == seen  # the booleans started no thread in any worker


def test_a_lone_worker_keeps_the_threads():
    # fewer workers than cores: manifold3d may use the cores the other workers would have
    from formgraph.sweeps import cluster

    with cluster.connect(None, workers=1) as client:
        preloads = client.run(lambda dask_worker: [p.name for p in dask_worker.preloads])
    assert all(p == [] for p in preloads.values())
