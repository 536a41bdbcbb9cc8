"""The node registry: its sorted copy follows every change, however it is made."""

from __future__ import annotations

import dataclasses

import pytest

import formgraph as fg
from formgraph.core import registry


def test_node_types_sorted_and_a_copy():
    types = fg.node_types()
    assert list(types) == sorted(types)
    types.pop("points.circle")
    assert "points.circle" in fg.node_types()  # the caller's dict is its own


def test_in_place_replacement_and_removal_are_seen(monkeypatch):
    spec = registry._REGISTRY["points.circle"]
    monkeypatch.setitem(registry._REGISTRY, "points.circle", dataclasses.replace(spec, version=99))
    assert fg.node_types()["points.circle"].version == 99
    monkeypatch.delitem(registry._REGISTRY, "points.circle")
    assert "points.circle" not in fg.node_types()
    monkeypatch.undo()
    assert fg.node_types()["points.circle"] is spec


def test_registration_is_seen():
    @registry.node("stub.registry_probe")
    def probe(x: float = 1.0) -> float:
        """A probe.

        Parameters
        ----------
        x : float
            Anything.
        """
        return x

    try:
        assert "stub.registry_probe" in fg.node_types()
    finally:
        del registry._REGISTRY["stub.registry_probe"]
    assert "stub.registry_probe" not in fg.node_types()


def test_input_error_call_names_the_port_unless_an_inner_input_did():
    from formgraph.core.errors import InputError

    def kernel(x):
        if x < 0:
            raise ValueError("x must not be negative")
        if x == 0:
            raise InputError("inner", "zero is refused by the inner input")
        return 2 * x

    assert InputError.call("outer", kernel, 2) == 4
    with pytest.raises(InputError, match="negative") as bad:
        InputError.call("outer", kernel, -1)
    assert bad.value.port == "outer"
    with pytest.raises(InputError, match="zero") as inner:
        InputError.call("outer", kernel, 0)
    assert inner.value.port == "inner"  # it named its own input: kept
    with pytest.raises(TypeError):  # not a complaint about a value: not rewrapped
        InputError.call("outer", kernel, "a")


def test_a_node_name_says_where_its_code_is():
    """``mesh.offset`` is under nodes/mesh/: one package per family prefix (SPEC layout)."""
    misplaced = {
        name: spec.func.__module__
        for name, spec in fg.node_types().items()
        if spec.func.__module__.startswith("formgraph.nodes.")
        and not spec.func.__module__.startswith(f"formgraph.nodes.{spec.family}.")
    }
    assert not misplaced
    families = {spec.family for spec in fg.node_types().values()}
    assert {"mesh", "curves", "nurbs", "field", "export", "read"} <= families
