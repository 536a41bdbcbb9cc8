"""An optimisation study whose workers are SLURM jobs, started by dask-jobqueue.

    pip install dask-jobqueue        # on the login node only; formgraph does not need it
    python examples/slurm/optimize_on_slurm.py

dask-jobqueue submits each worker as a batch job and the scheduler runs here; the study
talks to it like any Dask cluster. The cache folder is on a filesystem every node mounts
(``shared_cache=True``): a node one worker computed is loaded by every other, and by the
next study.
"""

from __future__ import annotations

import os

from dask_jobqueue import SLURMCluster
from distributed import Client

import formgraph as fg

SHARED = os.environ.get("FORMGRAPH_SHARED_CACHE", "/shared/formgraph-cache")

if __name__ == "__main__":
    cluster = SLURMCluster(
        cores=1,  # one single-threaded worker per job: the kernels are numpy, one core each
        processes=1,
        memory="4GB",
        walltime="02:00:00",
        job_script_prologue=[
            "export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1",
            f"source {os.path.expanduser('~/formgraph/.venv/bin/activate')}",
        ],
    )
    cluster.scale(jobs=32)
    with Client(cluster) as client:
        study = fg.optimize(
            "graphs/lamp_shade.yaml",
            vary={"wall": "0.02:0.3", "window": "0.05:0.5", "height": "0.6:2.2"},
            minimize=["size.volume"],
            constraints=[
                "8 * pi * window**2 >= 1.2",
                "size.parts <= 1",
                "wall**3 * (1 - window / 0.6) >= 5e-5",
            ],
            budget=400,
            batch=32,  # one trial per worker at a time
            client=client,
            cache_dir=SHARED,
            shared_cache=True,
            out="out/lamp_on_slurm",
        )
        print(study.summary())
    cluster.close()
