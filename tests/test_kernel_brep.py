"""The OpenCASCADE layer: our NURBS to OCC exactly (degree, knots with multiplicities,
weights), curves told apart into lines, arcs and splines, solids serialised (BinTools)
through pickling and the disk cache, and OCP never imported by ``import formgraph``."""

from __future__ import annotations

import pickle
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg

pytest.importorskip("OCP")

from formgraph.geometry import Solid  # noqa: E402
from formgraph.kernels.brep import convert, occ  # noqa: E402
from formgraph.kernels.nurbs import curve_evaluate, surface_evaluate  # noqa: E402


def _knots(rng: np.random.Generator, n: int, p: int) -> np.ndarray:
    inner = np.sort(rng.uniform(0.05, 0.95, n - p - 1))
    if len(inner) > 2 and p >= 2:
        inner[1] = inner[0]  # a knot of multiplicity 2 inside
    return np.concatenate([[0.0] * (p + 1), inner, [1.0] * (p + 1)])


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 5), st.integers(0, 6), st.booleans(), st.integers(0, 2**31))
def test_curves_go_to_occ_exactly(p, extra, rational, seed):
    rng = np.random.default_rng(seed)
    n = p + 1 + extra + 2
    cp = rng.normal(size=(n, 3)) * 10
    k = _knots(rng, n, p)
    w = rng.uniform(0.3, 3.0, n) if rational else None
    c = convert.bspline_curve(cp, p, k, w)
    assert c.Degree() == p and c.NbPoles() == n and c.IsRational() == rational
    values, counts = np.unique(k, return_counts=True)
    assert [c.Knot(i) for i in range(1, c.NbKnots() + 1)] == values.tolist()
    assert [c.Multiplicity(i) for i in range(1, c.NbKnots() + 1)] == counts.tolist()
    if rational:
        assert [c.Weight(i) for i in range(1, n + 1)] == w.tolist()
    t = np.linspace(0, 1, 41)
    ours = curve_evaluate(cp, p, k, w, t)
    theirs = np.array([occ.point(c.Value(x)) for x in t])
    np.testing.assert_allclose(theirs, ours, rtol=0, atol=1e-11 * np.abs(cp).max())


def test_unclamped_curves_are_clamped_without_moving():
    rng = np.random.default_rng(3)
    cp = rng.normal(size=(7, 3))
    k = np.arange(11, dtype=float)  # uniform, unclamped, degree 3: domain [3, 7]
    c = convert.bspline_curve(cp, 3, k, None)
    t = np.linspace(3, 7, 17)
    ours = curve_evaluate(cp, 3, k, None, t)
    theirs = np.array([occ.point(c.Value(x)) for x in t])
    np.testing.assert_allclose(theirs, ours, atol=1e-12)


def test_surfaces_go_to_occ_exactly():
    rng = np.random.default_rng(7)
    cp = rng.normal(size=(5, 4, 3))
    ku = np.array([0, 0, 0, 0.3, 0.6, 1, 1, 1.0])
    kv = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
    w = rng.uniform(0.5, 2, (5, 4))
    s = convert.bspline_surface(cp, 2, 3, ku, kv, w)
    assert (s.UDegree(), s.VDegree(), s.NbUPoles(), s.NbVPoles()) == (2, 3, 5, 4)
    uv = rng.uniform(0, 1, (30, 2))
    ours = surface_evaluate(cp, 2, 3, ku, kv, w, uv[:, 0], uv[:, 1])
    theirs = np.array([occ.point(s.Value(u, v)) for u, v in uv])
    np.testing.assert_allclose(theirs, ours.reshape(-1, 3), atol=1e-12)


def test_a_rounded_rectangle_is_four_lines_and_four_arcs():
    g = fg.Graph()
    g.add("r", "curves.rectangle", size=[30, 20], radius=4)
    r = g.evaluate("r")
    pieces = convert.curve_pieces(r.control_points, r.degree, r.knots, r.weights)
    assert sorted(p.kind for p in pieces) == ["arc"] * 4 + ["line"] * 4
    for p in pieces:
        if p.kind == "arc":
            assert p.radius == pytest.approx(4, abs=1e-12)


def test_a_circle_is_one_closed_circular_edge():
    g = fg.Graph()
    g.add("c", "nurbs.circle", radius=3, center=[1, 2, 0])
    c = g.evaluate("c")
    (piece,) = convert.curve_pieces(c.control_points, c.degree, c.knots, c.weights)
    assert piece.kind == "arc"
    np.testing.assert_allclose(piece.center, [1, 2, 0], atol=1e-12)
    (edge,) = convert.edges_of([piece])
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    a = BRepAdaptor_Curve(edge)
    assert a.GetType() == GeomAbs_CurveType.GeomAbs_Circle
    assert a.Circle().Radius() == pytest.approx(3, rel=1e-15)


def _drilled() -> Solid:
    g = fg.Graph()
    g.add("b", "brep.box", size=[20, 20, 10])
    g.add("f", "brep.fillet", solid="@b", radius=2, edges="=z > 4")
    g.add("c", "brep.cylinder", radius=3, height=30)
    g.add("d", "brep.boolean", a="@f", b=["@c"], operation="difference")
    return g.evaluate("d")


def test_a_solid_pickles_through_its_binary_brep():
    s = _drilled()
    back = pickle.loads(pickle.dumps(s))
    assert isinstance(back, Solid) and back.key == s.key
    assert back.fingerprint() == s.fingerprint()
    assert occ.volume(back.shape) == pytest.approx(occ.volume(s.shape), rel=1e-12)
    assert occ.is_valid(back.shape)


def test_a_solid_comes_back_from_the_disk_cache(tmp_path):
    def graph():
        g = fg.Graph(cache_dir=tmp_path)
        g.add("b", "brep.box", size=10)
        g.add("f", "brep.fillet", solid="@b", radius=1)
        return g

    first = graph().evaluate("f")
    again = graph()
    second = again.evaluate("f")
    assert again.stats["f"].source == "disk"
    assert second.key == first.key
    assert occ.volume(second.shape) == pytest.approx(occ.volume(first.shape), rel=1e-12)


def test_damaged_bytes_are_refused():
    s = _drilled()
    data = bytes(s.brep)
    with pytest.raises(ValueError, match="not an OpenCASCADE binary shape"):
        Solid(b"garbage", "k")
    with pytest.raises(ValueError):
        Solid(data[: len(data) // 3], "k")


def test_a_solid_is_immutable():
    s = _drilled()
    with pytest.raises(AttributeError):
        s.key = "other"
    assert not s.brep.flags.writeable


def test_import_formgraph_does_not_import_ocp():
    code = "import sys, formgraph; assert 'OCP' not in sys.modules; print('ok')"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "ok", done.stderr


def test_without_ocp_the_check_says_how_to_install_it(monkeypatch, tmp_path):
    from formgraph import kernels

    monkeypatch.setattr(kernels.brep, "available", lambda: False)
    path = tmp_path / "g.yaml"
    path.write_text("nodes:\n  block:\n    type: brep.box\n    size: 10\n")
    with pytest.raises(
        fg.GraphError, match=r"g.yaml:3: node 'block'.*pip install 'formgraph\[brep\]'"
    ):
        fg.load(path).check()
