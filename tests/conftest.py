from __future__ import annotations

import atexit
import itertools
import os
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# Locally each run explores new examples, and what they find becomes an @example; CI
# replays the same ones on every run. Neither times a test: the machine is shared, and a
# slow draw (the too_slow health check) or a slow example (the 200 ms deadline) on a busy
# box is no defect of the code, so neither may fail a run by chance.
settings.register_profile("explore", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile(
    "ci", parent=settings.get_profile("explore"), derandomize=True, print_blob=True
)
settings.load_profile("ci" if os.environ.get("CI") else "explore")

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
# two test workers on two cores: BLAS threads would only fight each other
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import stubs  # noqa: E402,F401  (registers the stub.* node types for executor tests)

# The CLI caches in $XDG_CACHE_HOME/formgraph by default: a test that runs it must neither
# read what an earlier test, an earlier run or another checkout left there (a hit instead of
# a computation depends on test order and on the machine) nor fill the user's cache. Each
# test gets its own, made only if something writes to it.
_CACHE_HOMES = Path(tempfile.mkdtemp(prefix="formgraph-test-caches-"))
atexit.register(shutil.rmtree, _CACHE_HOMES, ignore_errors=True)
_cache_home_numbers = itertools.count()


@pytest.fixture(autouse=True)
def _clear_run_record(monkeypatch):
    stubs.CALLS.clear()
    home = _CACHE_HOMES / str(next(_cache_home_numbers))
    monkeypatch.setenv("XDG_CACHE_HOME", str(home))
    yield
    shutil.rmtree(home, ignore_errors=True)


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
