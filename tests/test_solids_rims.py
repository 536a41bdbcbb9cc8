"""mesh.solidify's planar rims (nodes/mesh/offset.py, kernels/mesh/solidify.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.geometry import Field
from formgraph.kernels.mesh.solidify import planar_rim_directions

ROOT = Path(__file__).resolve().parents[1]


def shade(planar: bool) -> tuple[fg.Mesh, fg.Mesh]:
    g = fg.load(ROOT / "graphs" / "lamp_shade.yaml")
    g.add("s", "mesh.solidify", mesh="@band_mesh", thickness=0.08, offset=-1, planar_rims=planar)
    return g.evaluate("band_mesh"), g.evaluate("s")


def test_the_shade_stands_on_z0_and_keeps_its_wall():
    band, shell = shade(True)
    assert shell.is_watertight and shell.volume > 0
    assert shell.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    bottom = np.abs(shell.vertices[:, 2]) < 1e-12
    assert bottom.sum() == 2 * (np.abs(band.vertices[:, 2]) < 1e-12).sum()  # both copies
    # the rim's inner copy is a wall's thickness from the surface, measured on the surface
    n = band.n_vertices
    back = shell.vertices[n:][np.abs(band.vertices[:, 2]) < 1e-12]
    d = np.abs(Field.from_mesh(band).evaluate(back))
    assert d == pytest.approx(np.full(len(d), 0.08), rel=0.05)


def test_without_the_option_the_rim_sinks_below_the_bed():
    _, shell = shade(False)
    assert shell.vertices[:, 2].min() < -0.01


def test_non_planar_and_flat_rims_move_along_their_normals():
    # a flat sheet: its rim lies in its own plane, so nothing may move within it
    plane = fg.Graph()
    plane.add("p", "mesh.plane", size=[2, 2], divisions=[4, 4])
    plane.add("s", "mesh.solidify", mesh="@p", thickness=0.2)
    out = plane.evaluate("s")
    assert out.is_watertight and out.volume == pytest.approx(0.8, rel=1e-9)
    v = np.array([[0, 0, 0], [1, 0, 0.5], [1, 1, 0], [0, 1, 0.5]], dtype=float)
    e = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    n = np.tile([0.0, 0.0, 1.0], (4, 1))
    np.testing.assert_array_equal(planar_rim_directions(v, e, n), n)  # a saddle: not planar


def revolved(profile: list[list[float]], offset: float, wall: float, u: int = 64, v: int = 48):
    """A profile curve (x, 0, z) revolved about z, tessellated open at both ends, and the
    surface thickened: (surface, shell)."""
    g = fg.Graph()
    g.add("profile", "nurbs.interpolate", points=profile)
    g.add("sweep", "nurbs.revolve", curve="@profile", axis=[0, 0, 1])
    g.add("tube", "nurbs.tessellate", surface="@sweep", u=u, v=v)
    g.add("shell", "mesh.solidify", mesh="@tube", thickness=wall, offset=offset)
    return g.evaluate("tube"), g.evaluate("shell")


POT = [[1.2, 0, 3], [0.8, 0, 2], [1.5, 0, 1], [1, 0, 0]]  # the README's pot


def triangles(m: fg.Mesh) -> np.ndarray:
    from formgraph.kernels.io.meshdata import fan_triangles

    return fan_triangles(m.face_indices, m.face_offsets)


def check_shell(surface: fg.Mesh, shell: fg.Mesh, bottom: float, top: float) -> None:
    """No vertex past the rims' planes, closed, outward, and no face in a rim plane facing
    into the material (the wall folded back along the bed)."""
    import trimesh

    z = shell.vertices[:, 2]
    size = float(np.ptp(shell.vertices, axis=0).max())
    assert z.min() >= bottom - 1e-12 * size and z.max() <= top + 1e-12 * size
    t = trimesh.Trimesh(shell.vertices, triangles(shell), process=False)
    assert shell.is_watertight and t.is_winding_consistent and t.volume > 0
    corners = shell.vertices[triangles(shell)]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    for level, facing in ((bottom, -1), (top, 1)):
        flat = np.all(np.abs(corners[:, :, 2] - level) <= 1e-9 * size, axis=1)
        big = np.linalg.norm(normal[flat], axis=1) > 1e-12 * size**2
        assert (np.sign(normal[flat][big, 2]) == facing).all()


@pytest.mark.parametrize("offset", [-1.0, 0.0, 1.0])
def test_the_pot_stands_on_its_rims_planes_with_every_offset(offset):
    surface, shell = revolved(POT, offset, 0.1)
    check_shell(surface, shell, 0.0, 3.0)
    # the rings next to the rims: on or above the bed, on or below the top (the old wall
    # put 48 vertices at z = -0.030 with offset 1 and at z = 3.0235 with offset -1)
    n = surface.n_vertices
    for copy in (shell.vertices[:n], shell.vertices[n:]):
        assert copy[:, 2].min() >= -1e-12 and copy[:, 2].max() <= 3 + 1e-12


def test_the_pot_wall_holds_its_volume():
    import trimesh

    surface, centred = revolved(POT, 0.0, 0.1)
    area = trimesh.Trimesh(surface.vertices, triangles(surface), process=False).area
    inside, outside = (revolved(POT, k, 0.1)[1].volume for k in (-1.0, 1.0))
    # centred, the t^2 terms of the two sides cancel; the two one-sided walls differ by them
    # with opposite signs (Steiner's formula), so their mean is the centred one
    assert centred.volume == pytest.approx(area * 0.1, rel=0.005)
    assert (inside + outside) / 2 == pytest.approx(centred.volume, rel=0.005)
    assert inside < centred.volume < outside


@settings(max_examples=25, deadline=None)
@given(
    radii=st.lists(st.floats(0.8, 2.0), min_size=3, max_size=5),
    rise=st.floats(0.6, 1.5),
    wall=st.floats(0.02, 0.12),
    offset=st.sampled_from([-1.0, -0.5, 0.0, 0.5, 1.0]),
)
def test_random_revolved_walls_stay_between_their_rims_planes(radii, rise, wall, offset):
    profile = [[r, 0.0, k * rise] for k, r in enumerate(radii)]
    top = (len(radii) - 1) * rise
    surface, shell = revolved(profile, offset, wall, u=48, v=32)
    # rims the wall meets at 35 degrees or more (a wall nearly lying in its rim's plane
    # cannot be kept in it: those rims move along their normals, as documented)
    p = surface.vertices
    for end in (p[p[:, 2] <= 1e-9], p[p[:, 2] >= top - 1e-9]):
        x0 = end[np.argmax(end[:, 0]), 0]  # the rim vertex at angle 0 ...
        ring = p[(np.abs(p[:, 1]) < 1e-9) & (p[:, 0] > 0)]
        near = ring[np.argsort(np.abs(ring[:, 2] - end[0, 2]))[:2]]  # ... and its neighbour
        dr, dz = np.abs(near[1] - near[0])[[0, 2]]
        assume(np.degrees(np.arctan2(dz, dr)) >= 35 and x0 > 0)
    check_shell(surface, shell, 0.0, top)
    import trimesh

    area = trimesh.Trimesh(surface.vertices, triangles(surface), process=False).area
    if offset == 0.0:
        assert shell.volume == pytest.approx(area * wall, rel=0.03)
