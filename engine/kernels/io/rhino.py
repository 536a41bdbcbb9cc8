"""Rhino ``.3dm`` files through ``rhino3dm`` (McNeel's openNURBS, the format's reference).

NURBS go across exactly: degree, knots and weights. openNURBS stores ``n + p - 1`` knots (no
superfluous end knots; The NURBS Book's vector less its first and last) and control points
homogeneous (``w x, w y, w z, w``); both conversions are done here. Meshes go as meshes
(triangles and quads as they are, larger polygons fanned). Reading turns every curve type
(lines, arcs, polylines, poly-curves) into its NURBS form, every surface and every face of
a polysurface into its untrimmed NURBS surface, extrusions included.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["RhinoModel", "read_3dm", "write_3dm"]

Curve = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]
Surface = tuple[np.ndarray, int, int, np.ndarray, np.ndarray, "np.ndarray | None"]
MeshArrays = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass
class RhinoModel:
    curves: list[Curve] = field(default_factory=list)
    surfaces: list[Surface] = field(default_factory=list)
    meshes: list[MeshArrays] = field(default_factory=list)
    points: list[np.ndarray] = field(default_factory=list)
    untrimmed: int = 0  # polysurface faces read as their whole surfaces (trims dropped)


def _rhino_curve(r, c: Curve):
    cp, p, k, w = c
    rational = w is not None and not np.all(w == w[0])
    ww = np.ones(len(cp)) if w is None else np.asarray(w, dtype=np.float64)
    out = r.NurbsCurve(3, bool(rational), p + 1, len(cp))
    for i, (x, y, z) in enumerate(np.asarray(cp, dtype=np.float64)):
        wi = float(ww[i]) if rational else 1.0
        out.Points[i] = r.Point4d(x * wi, y * wi, z * wi, wi)
    for i, t in enumerate(np.asarray(k, dtype=np.float64)[1:-1]):
        out.Knots[i] = float(t)
    return out


def _rhino_surface(r, s: Surface):
    cp, du, dv, ku, kv, w = s
    nu, nv = cp.shape[:2]
    rational = w is not None and not np.all(w == w.flat[0])
    out = r.NurbsSurface.Create(3, bool(rational), du + 1, dv + 1, nu, nv)
    for i in range(nu):
        for j in range(nv):
            wi = float(w[i, j]) if rational else 1.0
            x, y, z = cp[i, j]
            out.Points[(i, j)] = r.Point4d(x * wi, y * wi, z * wi, wi)
    for i, t in enumerate(np.asarray(ku, dtype=np.float64)[1:-1]):
        out.KnotsU[i] = float(t)
    for i, t in enumerate(np.asarray(kv, dtype=np.float64)[1:-1]):
        out.KnotsV[i] = float(t)
    return out


def _rhino_mesh(r, m: MeshArrays):
    v, fi, fo = m
    out = r.Mesh()
    for x, y, z in np.asarray(v, dtype=np.float64):
        out.Vertices.Add(float(x), float(y), float(z))
    sizes = np.diff(fo)
    for k, size in enumerate(sizes):
        f = fi[fo[k] : fo[k + 1]]
        if size == 3:
            out.Faces.AddFace(int(f[0]), int(f[1]), int(f[2]))
        elif size == 4:
            out.Faces.AddFace(int(f[0]), int(f[1]), int(f[2]), int(f[3]))
        else:
            for j in range(1, size - 1):
                out.Faces.AddFace(int(f[0]), int(f[j]), int(f[j + 1]))
    return out


def write_3dm(
    *,
    curves: Sequence[Curve] = (),
    surfaces: Sequence[Surface] = (),
    meshes: Sequence[MeshArrays] = (),
    layers: Sequence[str] | None = None,
) -> bytes:
    """A Rhino 8 ``.3dm`` file of the objects, model units millimetres.

    ``layers`` names each object's layer (curves first, then surfaces, then meshes); by
    default ``curves``, ``surfaces`` and ``meshes``.
    """
    import rhino3dm as r

    model = r.File3dm()
    model.Settings.ModelUnitSystem = r.UnitSystem.Millimeters
    count = len(curves) + len(surfaces) + len(meshes)
    if layers is None:
        layers = ["curves"] * len(curves) + ["surfaces"] * len(surfaces) + ["meshes"] * len(meshes)
    if len(layers) != count:
        raise ValueError(f"{len(layers)} layers for {count} objects: give one each")
    index: dict[str, int] = {}
    for name in layers:
        if name not in index:
            layer = r.Layer()
            layer.Name = name
            index[name] = model.Layers.Add(layer)
    objects = (
        [_rhino_curve(r, c) for c in curves]
        + [_rhino_surface(r, s) for s in surfaces]
        + [_rhino_mesh(r, m) for m in meshes]
    )
    for geometry, name in zip(objects, layers, strict=True):
        if not geometry.IsValid:
            raise ValueError(f"rhino3dm finds the {type(geometry).__name__} invalid")
        attributes = r.ObjectAttributes()
        attributes.LayerIndex = index[name]
        model.Objects.Add(geometry, attributes)
    with tempfile.TemporaryDirectory() as folder:  # rhino3dm writes only to a path
        path = os.path.join(folder, "model.3dm")
        if not model.Write(path, 8):
            raise ValueError("rhino3dm could not write the model")
        with open(path, "rb") as fh:
            return fh.read()


def _curve_of(c) -> Curve:
    n = c.Points.Count if hasattr(c.Points, "Count") else len(c.Points)
    pw = np.array([[c.Points[i].X, c.Points[i].Y, c.Points[i].Z, c.Points[i].W] for i in range(n)])
    knots = np.array([c.Knots[i] for i in range(len(c.Knots))], dtype=np.float64)
    knots = np.concatenate([knots[:1], knots, knots[-1:]])
    w = pw[:, 3]
    rational = bool(c.IsRational) and not np.all(w == w[0])
    return pw[:, :3] / w[:, None], int(c.Degree), knots, (w if rational else None)


def _surface_of(s) -> Surface:
    nu, nv = s.Points.CountU, s.Points.CountV
    pw = np.array(
        [[list(_xyzw(s.Points.GetControlPoint(i, j))) for j in range(nv)] for i in range(nu)]
    )
    ku = np.array([s.KnotsU[i] for i in range(len(s.KnotsU))], dtype=np.float64)
    kv = np.array([s.KnotsV[i] for i in range(len(s.KnotsV))], dtype=np.float64)
    ku = np.concatenate([ku[:1], ku, ku[-1:]])
    kv = np.concatenate([kv[:1], kv, kv[-1:]])
    w = pw[..., 3]
    rational = bool(s.IsRational) and not np.all(w == w.flat[0])
    return pw[..., :3] / w[..., None], s.OrderU - 1, s.OrderV - 1, ku, kv, (w if rational else None)


def _xyzw(p) -> tuple[float, float, float, float]:
    return (p.X, p.Y, p.Z, p.W)


def read_3dm(data: bytes) -> RhinoModel:
    """The curves, surfaces, meshes and points of a ``.3dm`` file, in its model units.

    Raises
    ------
    ValueError
        For bytes openNURBS cannot read.
    """
    import rhino3dm as r

    model = r.File3dm.FromByteArray(data)
    if model is None:
        raise ValueError("not a Rhino .3dm file (openNURBS cannot read it)")
    out = RhinoModel()
    for obj in model.Objects:
        g = obj.Geometry
        if isinstance(g, r.Mesh):
            v = np.array([[p.X, p.Y, p.Z] for p in g.Vertices])
            faces = [tuple(g.Faces[k]) for k in range(g.Faces.Count)]
            sizes = np.array([3 if f[2] == f[3] else 4 for f in faces], dtype=np.int64)
            fi = np.array([i for f, s in zip(faces, sizes, strict=True) for i in f[:s]], np.int64)
            out.meshes.append((v.reshape(-1, 3), fi, np.concatenate([[0], np.cumsum(sizes)])))
        elif isinstance(g, r.Point):
            p = g.Location
            out.points.append(np.array([[p.X, p.Y, p.Z]]))
        elif isinstance(g, r.PointCloud):
            out.points.append(np.array([[p.X, p.Y, p.Z] for p in g.GetPoints()]).reshape(-1, 3))
        elif isinstance(g, r.Curve):
            out.curves.append(_curve_of(g.ToNurbsCurve()))
        elif isinstance(g, r.Brep):
            for k in range(len(g.Faces)):
                face = g.Faces[k]
                out.surfaces.append(_surface_of(face.ToNurbsSurface()))
                out.untrimmed += 1
        elif isinstance(g, r.Extrusion):
            out.surfaces.append(_surface_of(g.ToNurbsSurface()))
        elif isinstance(g, r.Surface):
            out.surfaces.append(_surface_of(g.ToNurbsSurface()))
    return out
