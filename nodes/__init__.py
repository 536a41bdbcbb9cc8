"""Node families of formgraph: one package per family prefix, its modules by topic.

A node's name says where its code is: ``mesh.offset`` is under ``nodes/mesh/``. Every module
below this package is imported here, so a new family or topic needs no list to edit. Modules
whose names start with ``_`` hold helpers shared by several nodes and register nothing.
"""

from __future__ import annotations

import importlib
import pkgutil

for _info in sorted(pkgutil.walk_packages(__path__, f"{__name__}."), key=lambda m: m.name):
    if not _info.name.rsplit(".", 1)[-1].startswith("_"):
        importlib.import_module(_info.name)
