"""Hostile attributes and per-element expressions: non-finite values, reserved and bad
names, wrong shapes, wires mixed into per-element lists, and attempts to write to them."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import formgraph as fg
from formgraph.geometry import Mesh, Points


def _graph(text: str) -> fg.Graph:
    return fg.Graph.from_text("formgraph: 1\nnodes:\n" + text, file="h.yaml")


GRID = (
    "  q: {type: points.grid, nx: 3, ny: 2}\n"
    '  p: {type: attr.set, geometry: "@q", name: normal, value: [0, 0, 1]}\n'
)


@pytest.mark.parametrize(
    ("value", "why"),
    [
        ('"=noise(x / 0, y, z)"', "not finite at element"),
        ('"=log(x - 5)"', "not finite at element 0"),
        ('"=rand(i) ** 1e308 + 1e308 * 10"', "not finite"),
        ('["=x", "=nothing"]', "names 'nothing'"),
        ('"=_x"', "starting with '_'"),
        ('["=normal", 0]', "component 0 of .* gives \\(3,\\) values per element"),
    ],
)
def test_bad_per_element_values_are_located_errors(value, why):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and numpy stays quiet
        with pytest.raises((fg.NodeError, fg.GraphError), match=rf"node 's'.*{why}"):
            g = _graph(GRID + f'  s: {{type: attr.set, geometry: "@p", name: h, value: {value}}}\n')
            g.evaluate("s")


@pytest.mark.parametrize("name", ["x", "count", "nx", "2h", "_h", "a-b"])
def test_names_that_expressions_could_not_read_are_refused(name):
    g = _graph(GRID + f'  s: {{type: attr.set, geometry: "@p", name: "{name}", value: 1}}\n')
    with pytest.raises(fg.NodeError, match=r"node 's', input 'name'"):
        g.evaluate("s")


def test_rand_of_extreme_keys_stays_in_range():
    g = _graph(
        GRID + '  s: {type: attr.set, geometry: "@p", name: r, value: "=rand(x * 1e308, -0.0)"}\n'
    )
    r = g.evaluate("s").point_data["r"]
    assert np.all((r >= 0) & (r < 1))


def test_a_wire_in_a_per_element_list_is_an_ordinary_input():
    with pytest.raises(fg.GraphError, match="node 'c', input 'rotate'.*unknown param 'i'"):
        _graph(
            GRID
            + "  b: {type: mesh.box}\n"
            + '  c: {type: mesh.copy_to_points, mesh: "@b", points: "@p", '
            + 'rotate: ["@b", 0, "=i"]}\n'
        )


def test_attributes_of_a_cached_value_cannot_be_written():
    g = _graph(GRID + '  s: {type: attr.set, geometry: "@p", name: h, value: "=x"}\n')
    h = g.evaluate("s").point_data["h"]
    with pytest.raises(ValueError):
        h[0] = 5
    with pytest.raises(ValueError):
        h.flags.writeable = True
    assert g.evaluate("s").point_data["h"][0] == 0.0


@pytest.mark.parametrize(
    "data",
    [{"h": object()}, {"h": [[1, 2], [3]]}, {"h": np.full(4, np.inf)}, {7: np.zeros(4)}, "h"],
)
def test_bad_attribute_data_from_python_is_a_value_error(data):
    with pytest.raises(ValueError):
        Mesh([[0, 0], [1, 0], [0, 1], [1, 1]], [[0, 1, 2], [1, 3, 2]], point_data=data)
    with pytest.raises(ValueError):
        Points(np.zeros((4, 3)), data)
