"""Helpers the test modules share: the CLI in a subprocess and admesh's STL report."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

needs_admesh = pytest.mark.skipif(
    shutil.which("admesh") is None, reason="admesh not installed (apt admesh)"
)


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run ``formgraph ARGS`` as a user would, in a fresh interpreter."""
    return subprocess.run(
        [sys.executable, "-m", "formgraph.cli.main", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


def admesh(path: Path) -> dict[str, float]:
    """admesh's report on an STL file: every ``Name : number`` figure it prints.

    ``open`` is its count of facets with one disconnected edge (the open edges).
    """
    report = subprocess.run(["admesh", str(path)], capture_output=True, text=True).stdout
    # "Name : value" pairs, two to a line in its statistics table; a facet row gives the
    # figure of the original file first
    out = {
        m.group(1).strip(): float(m.group(2))
        for m in re.finditer(r"([A-Za-z][A-Za-z0-9 ]*?)\s*:\s*(-?[\d.]+)", report)
    }
    out["open"] = out.get("Facets with 1 disconnected edge", float("nan"))
    return out
