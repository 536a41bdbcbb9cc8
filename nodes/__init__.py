"""Node families of formgraph: one module per family, each registering its nodes on import.

Every module in this package is imported here, so a new family needs no list to edit.
"""

from __future__ import annotations

import importlib
import pkgutil

for _info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
    if not _info.name.startswith("_"):
        importlib.import_module(f"{__name__}.{_info.name}")
