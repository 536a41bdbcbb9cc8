from __future__ import annotations

import os

import pytest
from hypothesis import settings

# CI replays the same examples on every run (a fresh clone's result must not depend on the
# draw); locally each run explores new ones, and what they find becomes an @example
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
# two test workers on two cores: BLAS threads would only fight each other
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import stubs  # noqa: E402,F401  (registers the stub.* node types for executor tests)


@pytest.fixture(autouse=True)
def _clear_run_record():
    stubs.CALLS.clear()
    yield


@pytest.fixture
def keep_locale():
    """lib3mf's writer sets the process's locale to "C" and leaves it there, which turns
    Python's default text encoding into ASCII for every later test: put it back."""
    import locale

    saved = locale.setlocale(locale.LC_ALL, None)
    yield
    locale.setlocale(locale.LC_ALL, saved)


def _needs_brep(path: object) -> bool:
    """Whether an example graph uses the brep extra (OpenCASCADE): its brep.* nodes or
    read.step, which without it fail the check with the install sentence."""
    from pathlib import Path

    if not isinstance(path, Path) or path.suffix != ".yaml":
        return False
    text = path.read_text()
    return "type: brep." in text or "type: read.step" in text


def pytest_collection_modifyitems(config, items):
    """Every test parametrized over graphs/ skips, saying why, the graphs that need the
    optional brep extra where OpenCASCADE is not installed."""
    import importlib.util

    if importlib.util.find_spec("OCP") is not None:
        return
    skip = pytest.mark.skip(reason="needs OpenCASCADE: pip install 'formgraph[brep]'")
    for item in items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if any(_needs_brep(v) for v in params.values()):
            item.add_marker(skip)
