"""The immutable geometry values that flow along wires.

Every type is a frozen dataclass over read-only float64/int64 arrays, so a node can never
change what another node sees. Each has ``to_pyvista()`` (pyvista imported lazily),
``nbytes`` (for the memory cache) and ``state()`` / :func:`from_state` (plain arrays and
JSON-able scalars, for the on-disk cache; no pickle).

The math lives in :mod:`formgraph.kernels`; these classes are thin, validated wrappers.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .kernels.mesh import grid as _grid


def is_frozen(a: Any) -> bool:
    """Whether nobody can ever write to array ``a``: read-only all the way to an immutable
    ``bytes`` buffer (an array that owns its data could be made writable again)."""
    if not isinstance(a, np.ndarray) or a.flags.writeable:
        return False
    base: Any = a
    while isinstance(base, np.ndarray):
        base = base.base
    return isinstance(base, bytes)


def frozen_array(values: Any, dtype: Any = np.float64) -> np.ndarray:
    """A C-contiguous array of ``values`` that nobody can write to, or make writable.

    The data are copied once into an immutable ``bytes`` buffer and viewed from there, so
    ``a.flags.writeable = True`` raises (for ``a`` and for ``a.base``). An array that is
    already frozen is shared as it is, never copied.
    """
    if is_frozen(values) and values.dtype == dtype and values.flags.c_contiguous:
        return values
    a = np.asarray(values, dtype=dtype)
    return np.frombuffer(a.tobytes(order="C"), dtype=a.dtype).reshape(a.shape)


def as_xyz(values: Any, what: str = "points") -> np.ndarray:
    """``(n, 2)`` or ``(n, 3)`` coordinates as a read-only ``(n, 3)`` float64 array (z = 0)."""
    frozen = is_frozen(values) and values.dtype == np.float64 and values.flags.c_contiguous
    if frozen and values.ndim == 2 and values.shape[1] == 3 and np.isfinite(values).all():
        return values  # immutable and valid already (another value's coordinates): shared
    try:
        raw = np.asarray(values)
        if raw.dtype.kind not in "biuf":
            raise TypeError  # strings, objects: not coordinates
        a = raw.astype(np.float64, copy=False)
    except (TypeError, ValueError, OverflowError):
        raw = None
        a = _pad_rows(values, what)
    if raw is not None and raw.dtype.kind == "b":
        raise ValueError(f"{what} must be numbers, not true/false")
    if a.ndim == 1 and a.size in (2, 3):
        a = a[None, :]
    if a.size == 0 and a.shape in ((0,), (0, 2), (0, 3)):
        a = a.reshape(0, 3)
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(
            f"{what} must be a list of [x, y] or [x, y, z] coordinates, got an array of shape "
            f"{a.shape}"
        )
    if a.shape[1] == 2:
        a = np.column_stack([a, np.zeros(len(a))])
    if not np.all(np.isfinite(a)):
        bad = int(np.argwhere(~np.isfinite(a))[0, 0])
        raise ValueError(f"{what}: coordinate {bad} is not finite ({a[bad].tolist()})")
    return frozen_array(a)


def _number(x: Any) -> float:
    if isinstance(x, (str, bytes, bool)) or not isinstance(x, (int, float, np.number)):
        raise TypeError(f"{x!r} is not a number")
    return float(x)


def _pad_rows(values: Any, what: str) -> np.ndarray:
    """Mixed [x, y] and [x, y, z] rows (z = 0 where it is missing)."""
    try:
        rows = [[_number(x) for x in r] for r in values]
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{what} must be a list of [x, y] or [x, y, z] numbers") from None
    for i, r in enumerate(rows):
        if len(r) not in (2, 3):
            raise ValueError(
                f"{what}: point {i} has {len(r)} coordinates; give [x, y] or [x, y, z]"
            )
    return np.array([r + [0.0] * (3 - len(r)) for r in rows], dtype=np.float64).reshape(-1, 3)


class Geometry:
    """Base of the geometry types."""

    @property
    def nbytes(self) -> int:
        return sum(v.nbytes for v in vars(self).values() if isinstance(v, np.ndarray))

    def to_pyvista(self) -> Any:  # pragma: no cover - overridden
        raise NotImplementedError

    def state(self) -> dict[str, Any]:
        """Arrays and JSON-able scalars that rebuild this value with :func:`from_state`."""
        raise NotImplementedError(f"{type(self).__name__} cannot be stored on disk")

    def fingerprint(self) -> Any:
        """What determines this value, for content hashes (its state, by default)."""
        return self.state()

    def __reduce_ex__(self, protocol: Any) -> Any:
        # pickled (e.g. to a worker process) as its state and rebuilt through the
        # constructor, so the copy is validated and as frozen as the original
        name = type(self).__name__
        if STORABLE.get(name) is type(self):
            return from_state, (name, self.state())
        return super().__reduce_ex__(protocol)


# ---------------------------------------------------------------------------------- points


@dataclass(frozen=True, eq=False, init=False)
class Points(Geometry):
    """A set of points. ``xyz`` is ``(n, 3)`` float64; ``np.asarray(points)`` gives it.

    Example
    -------
    >>> Points([[0, 0], [1, 2]]).xyz.tolist()
    [[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]]
    """

    xyz: np.ndarray

    def __init__(self, xyz: Any):
        object.__setattr__(self, "xyz", as_xyz(xyz))

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.xyz if dtype is None else self.xyz.astype(dtype)

    def __len__(self) -> int:
        return len(self.xyz)

    def __repr__(self) -> str:
        return f"Points(n={len(self.xyz)})"

    def to_pyvista(self) -> Any:
        import pyvista as pv

        return pv.PolyData(np.array(self.xyz))

    def state(self) -> dict[str, Any]:
        return {"xyz": self.xyz}


# ---------------------------------------------------------------------------------- curves


class Curve(Geometry):
    """The curve protocol: ``domain``, ``evaluate(t)``, ``derivative(t, order)``, ``sample(n)``."""

    domain: tuple[float, float]

    def evaluate(self, t: Any) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def sample(self, n: int) -> np.ndarray:
        """``n`` points at parameters evenly spaced over the domain, ``(n, 3)``."""
        if n < 2:
            raise ValueError(f"sampling a curve needs at least 2 points, got {n}")
        return self.evaluate(np.linspace(self.domain[0], self.domain[1], n))

    @property
    def closed(self) -> bool:
        a, b = self.evaluate(np.array(self.domain))
        scale = max(1.0, float(np.abs(self.sample(9)).max()))
        return bool(np.linalg.norm(a - b) <= 1e-9 * scale)

    def display_points(self) -> np.ndarray:
        """A polyline fine enough to draw this curve."""
        return self.sample(256)

    def to_pyvista(self) -> Any:
        import pyvista as pv

        return pv.lines_from_points(np.array(self.display_points()))


@dataclass(frozen=True, eq=False, init=False)
class NurbsCurve(Curve):
    """A NURBS curve, the exact curve type: polylines, Beziers, Catmull-Rom and circles.

    Parameters
    ----------
    control_points : (n, 3) or (n, 2) float
    degree : int
    knots : (n + degree + 1,) float, non-decreasing
    weights : (n,) float, positive; None for a non-rational curve (all ones)

    Evaluation is The NURBS Book's A2.1-A2.3 and A4.1-A4.2, vectorized over parameters
    (:mod:`formgraph.kernels.nurbs`).
    """

    control_points: np.ndarray
    degree: int
    knots: np.ndarray
    weights: np.ndarray
    rational: bool = field(default=False)

    def __init__(self, control_points: Any, degree: int, knots: Any, weights: Any = None):
        from .kernels import nurbs

        cp = as_xyz(control_points, "control_points")
        kn = frozen_array(knots)
        w = None if weights is None else frozen_array(weights)
        nurbs.validate_curve(cp, int(degree), kn, w)
        rational = w is not None and not np.all(w == w[0])
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "degree", int(degree))
        object.__setattr__(self, "knots", kn)
        object.__setattr__(self, "weights", w if w is not None else frozen_array(np.ones(len(cp))))
        object.__setattr__(self, "rational", bool(rational))

    @classmethod
    def polyline(cls, points: Any, closed: bool = False) -> NurbsCurve:
        """The degree-1 curve through ``points``; ``closed`` joins the last to the first.

        The parameter is the cumulative chord length, so t is arc length along it.
        """
        p = as_xyz(points)
        if len(p) < 2:
            raise ValueError(f"a polyline needs at least 2 points, got {len(p)}")
        if closed and not np.array_equal(p[0], p[-1]):
            p = np.vstack([p, p[:1]])
        # a repeated point (or one so close that the running length does not grow) adds no
        # segment; dropping it keeps the shape and the knots valid
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        keep = np.concatenate([[True], np.diff(chord) > 0])
        p, chord = p[keep], chord[keep]
        if len(p) < 2:
            raise ValueError("a polyline needs at least two distinct points")
        knots = np.concatenate([[chord[0]], chord, [chord[-1]]])
        return cls(p, 1, knots)

    @property
    def domain(self) -> tuple[float, float]:  # type: ignore[override]
        p = self.degree
        return float(self.knots[p]), float(self.knots[len(self.control_points)])

    def _w(self) -> np.ndarray | None:
        return self.weights if self.rational else None

    def evaluate(self, t: Any) -> np.ndarray:
        from .kernels import nurbs

        return nurbs.curve_evaluate(self.control_points, self.degree, self.knots, self._w(), t)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        from .kernels import nurbs

        scalar = np.ndim(t) == 0
        d = nurbs.curve_derivatives(
            self.control_points, self.degree, self.knots, self._w(), np.atleast_1d(t), order
        )[order]
        return d[0] if scalar else d

    def display_points(self) -> np.ndarray:
        if self.degree == 1:
            return self.control_points
        spans = max(1, len(np.unique(self.knots)) - 1)
        return self.sample(min(4096, max(64, 16 * spans)))

    def __repr__(self) -> str:
        kind = "rational " if self.rational else ""
        return f"NurbsCurve({kind}degree={self.degree}, n={len(self.control_points)})"

    def state(self) -> dict[str, Any]:
        return {
            "control_points": self.control_points,
            "degree": self.degree,
            "knots": self.knots,
            "weights": self.weights,
        }


@dataclass(frozen=True, eq=False)
class ParametricCurve(Curve):
    """A curve given by expressions ``x(t), y(t), z(t)`` over ``domain``.

    ``fx, fy, fz`` are callables taking ``t=array``; ``samples`` is how finely it is drawn
    and sampled by default. Derivatives are central finite differences.
    """

    fx: Callable[..., Any]
    fy: Callable[..., Any]
    fz: Callable[..., Any]
    domain: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]
    samples: int = 256

    def evaluate(self, t: Any) -> np.ndarray:
        scalar = np.ndim(t) == 0
        tt = np.atleast_1d(np.asarray(t, dtype=np.float64))
        cols = [
            np.broadcast_to(np.asarray(f(t=tt), dtype=np.float64), tt.shape)
            for f in (self.fx, self.fy, self.fz)
        ]
        xyz = np.stack(cols, axis=-1)
        bad = ~np.isfinite(xyz).all(axis=-1)
        if bad.any():
            i = int(np.argmax(bad))
            axis = "xyz"[int(np.argmax(~np.isfinite(xyz[i])))]
            text = getattr((self.fx, self.fy, self.fz)["xyz".index(axis)], "text", axis)
            raise ValueError(f"{axis} = {text!r} is not finite at t = {tt[i]:.6g}")
        return xyz[0] if scalar else xyz

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        t0, t1 = self.domain
        h = (t1 - t0) * 1e-5
        tt = np.clip(np.asarray(t, dtype=np.float64), t0 + order * h, t1 - order * h)
        if order == 1:
            return (self.evaluate(tt + h) - self.evaluate(tt - h)) / (2 * h)
        if order == 2:
            return (self.evaluate(tt + h) - 2 * self.evaluate(tt) + self.evaluate(tt - h)) / h**2
        raise ValueError(f"derivative order {order} is not supported on a parametric curve")

    def display_points(self) -> np.ndarray:
        return self.sample(max(2, self.samples))

    def __repr__(self) -> str:
        return f"ParametricCurve(domain={self.domain})"

    def fingerprint(self) -> Any:
        return {
            "f": [_expression_fingerprint(f) for f in (self.fx, self.fy, self.fz)],
            "domain": list(self.domain),
            "samples": self.samples,
        }

    @property
    def nbytes(self) -> int:
        return 256


# -------------------------------------------------------------------------------- surfaces


class Surface(Geometry):
    """The surface protocol: ``domain_u``, ``domain_v``, ``evaluate(u, v)``, ``tessellate``."""

    domain_u: tuple[float, float]
    domain_v: tuple[float, float]

    def evaluate(self, u: Any, v: Any) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points at every (u[i], v[j]): ``(len(u), len(v), 3)``."""
        return self.evaluate(u[:, None], v[None, :])

    def tessellate(self, nu: int = 32, nv: int = 32) -> Mesh:
        """A quad mesh of ``nu x nv`` faces over the whole domain (seams closed up)."""
        if nu < 1 or nv < 1:
            raise ValueError(f"tessellation needs at least 1 x 1 faces, got {nu} x {nv}")
        u = np.linspace(*self.domain_u, nu + 1)
        v = np.linspace(*self.domain_v, nv + 1)
        pts = self.evaluate_grid(u, v)
        closed_u = nu > 1 and bool(np.allclose(pts[0], pts[-1], atol=1e-10 * _scale(pts)))
        closed_v = nv > 1 and bool(np.allclose(pts[:, 0], pts[:, -1], atol=1e-10 * _scale(pts)))
        if closed_u:
            pts = pts[:-1]
        if closed_v:
            pts = pts[:, :-1]
        fi, fo = _grid.grid_faces(pts.shape[0], pts.shape[1], closed_u, closed_v)
        return Mesh(*_grid.collapse_poles(pts, fi, fo))

    def to_pyvista(self) -> Any:
        return self.tessellate(64, 64).to_pyvista()


def _expression_fingerprint(f: Any) -> Any:
    """A bound expression is its text and the param values it reads; any other callable
    cannot be hashed (its content is code), and says so."""
    text, params = getattr(f, "text", None), getattr(f, "params", None)
    if isinstance(text, str) and params is not None:
        return {"text": text, "params": dict(params)}
    raise TypeError("a curve or surface of plain Python callables has no content hash")


def _scale(pts: np.ndarray) -> float:
    return max(1.0, float(np.abs(pts).max()))


@dataclass(frozen=True, eq=False, init=False)
class NurbsSurface(Surface):
    """A tensor-product NURBS surface; ``control_points`` is ``(nu, nv, 3)``, u first."""

    control_points: np.ndarray
    degree_u: int
    degree_v: int
    knots_u: np.ndarray
    knots_v: np.ndarray
    weights: np.ndarray
    rational: bool = field(default=False)

    def __init__(
        self,
        control_points: Any,
        degree_u: int,
        degree_v: int,
        knots_u: Any,
        knots_v: Any,
        weights: Any = None,
    ):
        from .kernels import nurbs

        cp = frozen_array(control_points)
        if cp.ndim != 3 or cp.shape[2] not in (2, 3):
            raise ValueError(
                f"surface control points must be rows of [x, y, z] points (nu, nv, 3), got "
                f"shape {cp.shape}"
            )
        if cp.shape[2] == 2:
            cp = frozen_array(np.concatenate([cp, np.zeros(cp.shape[:2] + (1,))], axis=2))
        ku, kv = frozen_array(knots_u), frozen_array(knots_v)
        w = None if weights is None else frozen_array(weights)
        nurbs.validate_surface(cp, int(degree_u), int(degree_v), ku, kv, w)
        rational = w is not None and not np.all(w == w.flat[0])
        object.__setattr__(self, "control_points", cp)
        object.__setattr__(self, "degree_u", int(degree_u))
        object.__setattr__(self, "degree_v", int(degree_v))
        object.__setattr__(self, "knots_u", ku)
        object.__setattr__(self, "knots_v", kv)
        object.__setattr__(
            self, "weights", w if w is not None else frozen_array(np.ones(cp.shape[:2]))
        )
        object.__setattr__(self, "rational", bool(rational))

    def _args(self) -> tuple[Any, ...]:
        w = self.weights if self.rational else None
        return (self.control_points, self.degree_u, self.degree_v, self.knots_u, self.knots_v, w)

    @property
    def domain_u(self) -> tuple[float, float]:  # type: ignore[override]
        return float(self.knots_u[self.degree_u]), float(self.knots_u[self.control_points.shape[0]])

    @property
    def domain_v(self) -> tuple[float, float]:  # type: ignore[override]
        return float(self.knots_v[self.degree_v]), float(self.knots_v[self.control_points.shape[1]])

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        from .kernels import nurbs

        return nurbs.surface_evaluate(*self._args(), u, v)

    def evaluate_grid(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        from .kernels import nurbs

        return nurbs.surface_evaluate_grid(*self._args(), np.asarray(u), np.asarray(v))

    def normals(self, u: Any, v: Any) -> np.ndarray:
        from .kernels import nurbs

        return nurbs.surface_normals(*self._args(), u, v)

    def __repr__(self) -> str:
        nu, nv, _ = self.control_points.shape
        return f"NurbsSurface(degree=({self.degree_u}, {self.degree_v}), n=({nu}, {nv}))"

    def state(self) -> dict[str, Any]:
        return {
            "control_points": self.control_points,
            "degree_u": self.degree_u,
            "degree_v": self.degree_v,
            "knots_u": self.knots_u,
            "knots_v": self.knots_v,
            "weights": self.weights,
        }


@dataclass(frozen=True, eq=False)
class ParametricSurface(Surface):
    """A surface given by expressions ``x(u, v), y(u, v), z(u, v)``."""

    fx: Callable[..., Any]
    fy: Callable[..., Any]
    fz: Callable[..., Any]
    domain_u: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]
    domain_v: tuple[float, float] = (0.0, 1.0)  # type: ignore[assignment]

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        uu, vv = np.broadcast_arrays(np.asarray(u, np.float64), np.asarray(v, np.float64))
        cols = [
            np.broadcast_to(np.asarray(f(u=uu, v=vv), np.float64), uu.shape)
            for f in (self.fx, self.fy, self.fz)
        ]
        xyz = np.stack(cols, axis=-1)
        bad = ~np.isfinite(xyz).all(axis=-1)
        if bad.any():
            idx = np.unravel_index(int(np.argmax(bad)), bad.shape)
            axis = int(np.argmax(~np.isfinite(xyz[idx])))
            text = getattr((self.fx, self.fy, self.fz)[axis], "text", "xyz"[axis])
            raise ValueError(
                f"{'xyz'[axis]} = {text!r} is not finite at u = {uu[idx]:.6g}, v = {vv[idx]:.6g}"
            )
        return xyz

    def __repr__(self) -> str:
        return f"ParametricSurface(u={self.domain_u}, v={self.domain_v})"

    def fingerprint(self) -> Any:
        return {
            "f": [_expression_fingerprint(f) for f in (self.fx, self.fy, self.fz)],
            "domain": [list(self.domain_u), list(self.domain_v)],
        }

    @property
    def nbytes(self) -> int:
        return 256


# ------------------------------------------------------------------------------------ mesh


@dataclass(frozen=True, eq=False, init=False)
class Mesh(Geometry):
    """A polygon mesh with mixed face sizes, stored flat.

    Parameters
    ----------
    vertices : (n, 3) float
    face_indices : (sum of face sizes,) int
        Vertex indices of all faces, one face after another.
    face_offsets : (n_faces + 1,) int
        Face ``i`` is ``face_indices[face_offsets[i]:face_offsets[i + 1]]``.

    The half-edge connectivity (:attr:`halfedges`) is built on first use, vectorized, and
    raises on non-manifold edges, bad indices and inconsistent orientation.
    """

    vertices: np.ndarray
    face_indices: np.ndarray
    face_offsets: np.ndarray

    def __init__(self, vertices: Any, face_indices: Any, face_offsets: Any = None):
        v = as_xyz(vertices, "vertices")
        if face_offsets is None:  # a list of faces
            faces = [np.asarray(f, dtype=np.int64).ravel() for f in face_indices]
            sizes = np.array([len(f) for f in faces], dtype=np.int64)
            fi = np.concatenate(faces) if faces else np.zeros(0, np.int64)
            fo = np.concatenate([[0], np.cumsum(sizes)])
        else:
            fi = _indices(face_indices, "face_indices")
            fo = _indices(face_offsets, "face_offsets")
        if fo.size == 0 or fo[0] != 0 or fo[-1] != fi.size or np.any(np.diff(fo) < 0):
            raise ValueError(
                "face_offsets must start at 0, never decrease and end at len(face_indices)"
            )
        sizes = np.diff(fo)
        if sizes.size and sizes.min() < 3:
            bad = int(np.argmax(sizes < 3))
            raise ValueError(f"face {bad} has {int(sizes[bad])} vertices; a face needs at least 3")
        if fi.size and (fi.min() < 0 or fi.max() >= len(v)):
            pos = int(np.argmax((fi < 0) | (fi >= len(v))))
            face = int(np.searchsorted(fo, pos, side="right") - 1)
            raise ValueError(
                f"face {face} refers to vertex {int(fi[pos])}, but there are {len(v)} vertices"
            )
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "face_indices", frozen_array(fi, np.int64))
        object.__setattr__(self, "face_offsets", frozen_array(fo, np.int64))

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.face_offsets) - 1

    @property
    def face_sizes(self) -> np.ndarray:
        return np.diff(self.face_offsets)

    @property
    def faces(self) -> list[np.ndarray]:
        """Each face's vertex indices (a convenience; kernels use the flat arrays)."""
        if self.n_faces == 0:
            return []
        return np.split(self.face_indices, self.face_offsets[1:-1])

    @functools.cached_property
    def halfedges(self) -> Any:
        """Half-edge connectivity (:class:`formgraph.kernels.mesh.halfedge.HalfEdges`)."""
        from .kernels.mesh import build_halfedges

        return build_halfedges(self.face_indices, self.face_offsets, self.n_vertices)

    # measures (kernels in :mod:`formgraph.kernels.mesh.measure`), computed once per mesh

    @functools.cached_property
    def edge_table(self) -> Any:
        """Undirected edges with their face counts (:class:`~.kernels.mesh.measure.EdgeTable`)."""
        from .kernels.mesh import measure

        return measure.edge_table(self.face_indices, self.face_offsets, self.n_vertices)

    @functools.cached_property
    def area(self) -> float:
        """Total face area (Newell's vector per face: exact for planar polygons)."""
        from .kernels.mesh import measure

        return float(measure.face_areas(*self.state().values()).sum())

    @functools.cached_property
    def volume(self) -> float:
        """Signed enclosed volume by the divergence theorem: positive for a closed, outward
        mesh; only meaningful when :attr:`is_watertight`."""
        from .kernels.mesh import measure

        return float(measure.signed_volume(*self.state().values()).sum())

    @functools.cached_property
    def bounds(self) -> np.ndarray:
        """(2, 3) read-only: the lowest and highest corner of the vertices' bounding box."""
        v = self.vertices if self.n_vertices else np.zeros((1, 3))
        return frozen_array([v.min(axis=0), v.max(axis=0)])

    @property
    def is_watertight(self) -> bool:
        """Every edge lies on exactly two faces (no open or non-manifold edge)."""
        return self.n_faces > 0 and bool(np.all(self.edge_table.counts == 2))

    @property
    def euler_characteristic(self) -> int:
        """V - E + F, counting every vertex: 2 for a closed sphere-like mesh."""
        return self.n_vertices - self.edge_table.n_edges + self.n_faces

    @property
    def nbytes(self) -> int:
        return self.vertices.nbytes + self.face_indices.nbytes + self.face_offsets.nbytes

    def __repr__(self) -> str:
        return f"Mesh(n_vertices={self.n_vertices}, n_faces={self.n_faces})"

    def to_pyvista(self) -> Any:
        import pyvista as pv

        sizes = self.face_sizes
        cells = np.insert(self.face_indices, self.face_offsets[:-1], sizes)
        return pv.PolyData(np.array(self.vertices), faces=cells)

    def state(self) -> dict[str, Any]:
        return {
            "vertices": self.vertices,
            "face_indices": self.face_indices,
            "face_offsets": self.face_offsets,
        }


def _indices(values: Any, what: str) -> np.ndarray:
    a = np.asarray(values)
    if a.size and a.dtype.kind == "f" and not np.all(a == np.round(a)):
        raise ValueError(f"{what} must be whole numbers")
    if a.size and a.dtype.kind not in "iuf":
        raise ValueError(f"{what} must be whole numbers, got {a.dtype}")
    return a.astype(np.int64).ravel()


STORABLE: dict[str, type[Geometry]] = {
    cls.__name__: cls for cls in (Points, NurbsCurve, NurbsSurface, Mesh)
}


def from_state(type_name: str, state: dict[str, Any]) -> Geometry:
    """Rebuild a geometry value from :meth:`Geometry.state` (validated like any input)."""
    cls = STORABLE[type_name]
    return cls(**state)
