"""Hostile booleans: inputs that pass the edge-table check yet mislead manifold3d. Each ends
as the right solid or a sentence naming the input, never a silently wrong result."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import formgraph as fg

_BOX_V = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    float,
)
_BOX_F = np.array(
    [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
)


def _box(lo=0.0, size=1.0, extra=None) -> fg.Mesh:
    v = lo + size * _BOX_V
    if extra is not None:
        v = np.vstack([v, extra])
    return fg.Mesh(v, _BOX_F)


def _boolean(a, b, operation):
    g = fg.Graph(file="h.yaml")
    g.add("r", "mesh.boolean", a=a, b=b, operation=operation)
    return g.evaluate("r")


def _volume(m: fg.Mesh) -> float:
    t = trimesh.Trimesh(m.vertices, m.face_indices.reshape(-1, 3), process=False)
    assert t.is_watertight
    return float(t.volume)


def test_an_unused_far_vertex_does_not_erase_a_union():
    far = _box(extra=[[1e300, 0, 0]])
    g = fg.Graph()
    g.add("u", "mesh.union", meshes=[far, far])
    g.add("b", "mesh.boolean", a=far, b=_box(0.5))
    assert _volume(g.evaluate("u")) == pytest.approx(1.0)
    assert _volume(g.evaluate("b")) == pytest.approx(1.875)


@pytest.mark.parametrize("order", ["big first", "small first"])
def test_operands_too_different_in_size_are_refused_in_either_order(order):
    big, small = _box(size=1e20), _box()
    a, b, port = (big, small, "b") if order == "big first" else (small, big, "a")
    with pytest.raises(fg.NodeError, match=rf"input '{port}'.*too small beside the other"):
        _boolean(a, b, "intersection")


@pytest.mark.parametrize("order", ["big first", "small first"])
def test_a_coordinate_past_what_a_boolean_represents_is_refused(order):
    big, small = _box(size=1e300), _box()
    a, b, port = (big, small, "a") if order == "big first" else (small, big, "b")
    with pytest.raises(fg.NodeError, match=rf"input '{port}'.*coordinate of 1e\+300.*scale it"):
        _boolean(a, b, "intersection")


def _double(lo=0.0) -> fg.Mesh:
    v = lo + _BOX_V
    return fg.Mesh(np.vstack([v, v]), np.vstack([_BOX_F, _BOX_F + 8]))


@pytest.mark.parametrize(
    ("operation", "volume"), [("union", 1.875), ("difference", 0.875), ("intersection", 0.125)]
)
def test_two_coincident_copies_read_as_one_solid(operation, volume):
    other = _box(0.5)
    assert _volume(_boolean(_double(), other, operation)) == pytest.approx(volume)
    back = {"union": 1.875, "difference": 0.875, "intersection": 0.125}[operation]
    assert _volume(_boolean(other, _double(), operation)) == pytest.approx(back)


def test_a_collapsed_box_is_the_empty_solid_with_a_warning():
    for point in (0.0, 0.5, 5.0):  # at the origin manifold3d keeps its degenerate triangles
        dot = fg.Mesh(np.full((8, 3), point), _BOX_F)
        for operation, expected in (("intersection", 0.0), ("union", 1.0), ("difference", 0.0)):
            with pytest.warns(fg.FormgraphWarning, match=r"input a bounds no volume"):
                got = _boolean(dot, _box(), operation)
            assert (got.n_faces == 0) if expected == 0 else _volume(got) == pytest.approx(1.0)
        with pytest.warns(fg.FormgraphWarning, match=r"input b bounds no volume"):
            assert _volume(_boolean(_box(), dot, "difference")) == pytest.approx(1.0)
        g = fg.Graph()
        g.add("u", "mesh.union", meshes=[_box(), dot])
        assert _volume(g.evaluate("u")) == pytest.approx(1.0)


def test_overlapping_parts_around_a_cavity_are_refused():
    shell = trimesh.creation.box(extents=[4, 4, 4])
    cavity = trimesh.creation.box(extents=[1, 1, 1])
    cavity.invert()
    lump = trimesh.creation.box(extents=[1, 1, 1])
    lump.apply_translation([2, 0, 0])  # sticks out through the shell's wall
    t = trimesh.util.concatenate([shell, cavity, lump])
    m = fg.Mesh(t.vertices, t.faces)
    with pytest.raises(fg.NodeError, match=r"input 'a'.*2 solid parts that overlap.*1 cavit"):
        _boolean(m, _box(10), "union")
