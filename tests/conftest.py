from __future__ import annotations

import os

import pytest

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import stubs  # noqa: E402,F401  (registers the stub.* node types for executor tests)


@pytest.fixture(autouse=True)
def _clear_run_record():
    stubs.CALLS.clear()
    yield
