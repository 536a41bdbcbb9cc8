"""Design-space sweeps on Dask.

- ``api``: :func:`formgraph.sweep` and the :class:`Sweep` result (rows, ``sweep.csv``,
  the contact sheet)
- ``sampling``: the variants (grid, random, Latin hypercube) from ``--vary`` specs
- ``tasks``: the variants as one Dask graph whose tasks are node cache keys
- ``cluster``: running it on a local or remote Dask cluster
"""
