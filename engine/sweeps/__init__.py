"""Design-space sweeps on Dask.

- ``api``: :func:`formgraph.sweep` and the :class:`Sweep` result (rows, ``sweep.csv``,
  the contact sheet)
- ``sampling``: the variants (grid, random, Latin hypercube) from ``--vary`` specs
- ``tasks``: the variants as one Dask graph whose tasks are node cache keys
- ``cluster``: running it on a local or remote Dask cluster
- ``optimize``: :func:`formgraph.optimize`, optuna's samplers asking and the sweep's runner
  answering, batch by batch; ``objectives`` (objectives, constraints, the search space,
  the Pareto front), ``journal`` (``study.journal``), ``progress_plot`` (``progress.png``)
"""
