"""`Field`: a signed distance function, negative inside, as an immutable recipe.

A field is what built it: an operation (``sphere``, ``union``, ``from_mesh``, ...), its
parameters and the fields (or meshes, curves) it was made from. Evaluating it runs the
recipe on the points asked for (kernels in :mod:`formgraph.kernels.field`); nothing is
sampled ahead, and its content hash (:meth:`Field.fingerprint`) is the recipe's, never a
sampling's. A field knows its ``bounds`` when its construction gives them (a sphere, a
mesh's distance, an intersection with one of those), else ``None`` (a TPMS, an
expression), and ``lipschitz``, a bound on its gradient's length that the mesher's culling
relies on (1 for true distances and the blends of them).

A field is not kept in the disk cache (it is not in :data:`STORABLE`): it is a few numbers
and references, rebuilt in microseconds; the meshes made from it are what is stored.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .base import Geometry, _expression_fingerprint, frozen_array

__all__ = ["Field"]


def _box_union(boxes: list[np.ndarray | None]) -> np.ndarray | None:
    if any(b is None for b in boxes):
        return None
    return np.stack([np.min([b[0] for b in boxes], 0), np.max([b[1] for b in boxes], 0)])


def _box_intersection(boxes: list[np.ndarray | None]) -> np.ndarray | None:
    known = [b for b in boxes if b is not None]
    if not known:
        return None
    lo = np.max([b[0] for b in known], 0)
    hi = np.min([b[1] for b in known], 0)
    return np.stack([lo, np.maximum(hi, lo)])


def _grow(box: np.ndarray | None, by: float) -> np.ndarray | None:
    return None if box is None else np.stack([box[0] - by, box[1] + by])


class Field(Geometry):
    """A signed distance function (negative inside) over 3-D space.

    Build one with the class methods (:meth:`sphere`, :meth:`union`, ...) or the
    ``field.*`` nodes. ``field.evaluate(p)`` takes points (n, 3) and gives (n,) values.

    Attributes
    ----------
    op : str
        The operation that built it.
    args : Mapping[str, Any]
        Its parameters (numbers, read-only arrays, meshes, curves, expressions).
    children : tuple[Field, ...]
        The fields it combines.
    bounds : (2, 3) float or None
        A box outside which the field is positive (None: not known, give ``bounds``).
    lipschitz : float
        A bound on ``|grad f|`` (1 for a true distance).
    """

    def __init__(
        self,
        op: str,
        args: Mapping[str, Any] | None = None,
        children: tuple[Field, ...] = (),
        bounds: Any = None,
        lipschitz: float = 1.0,
    ):
        if op not in _OPS:
            raise ValueError(f"unknown field operation {op!r}")
        frozen = {
            k: frozen_array(v) if isinstance(v, np.ndarray) else v for k, v in (args or {}).items()
        }
        box = None if bounds is None else frozen_array(np.asarray(bounds, float).reshape(2, 3))
        object.__setattr__(self, "op", op)
        object.__setattr__(self, "args", _FrozenDict(frozen))
        object.__setattr__(self, "children", tuple(children))
        object.__setattr__(self, "bounds", box)
        object.__setattr__(self, "lipschitz", float(lipschitz))

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("a Field is immutable")

    # ------------------------------------------------------------------ evaluation

    def evaluate(self, points: Any) -> np.ndarray:
        """Values at ``points`` (n, 3) -> (n,) float64, negative inside."""
        p = np.asarray(points, dtype=np.float64)
        if p.ndim == 1:
            p = p.reshape(1, -1)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must be (n, 3), got shape {p.shape}")
        with np.errstate(all="ignore"):
            out = np.asarray(_OPS[self.op](self, p), dtype=np.float64)
        return np.broadcast_to(out, (len(p),)).copy() if out.shape != (len(p),) else out

    def __call__(self, points: Any) -> np.ndarray:
        return self.evaluate(points)

    @functools.cached_property
    def separable(self) -> bool:
        """Whether :meth:`evaluate_grid` works on tables along the axes all through (no
        point-wise fallback), so a lattice costs a fraction of its points."""
        if self.op not in _GRID:
            return False
        if self.op == "transform" and not np.array_equal(self.args["matrix"], np.eye(3)):
            return False
        return all(c.separable for c in self.children)

    def evaluate_grid(self, origin: Any, step: Any, shape: Any) -> np.ndarray:
        """Values on lattices of points: ``origin + (i, j, k) * step`` for ``0 <= (i, j,
        k) < shape``, one lattice per row of ``origin`` ((n, 3) -> (n, *shape); (3,) ->
        shape). The same values as :meth:`evaluate` at those points (to rounding); the
        field's key does not depend on which is used. Primitives whose distance is
        separable in the coordinates (TPMS, boxes, spheres) and the blends, shells,
        offsets and axis-aligned transforms of them work on tables along the axes; the
        rest are sampled point by point."""
        o = np.asarray(origin, dtype=np.float64)
        single = o.ndim == 1
        o = o.reshape(-1, 3)
        h = np.broadcast_to(np.asarray(step, dtype=np.float64), (3,))
        n = tuple(int(k) for k in shape)
        if len(n) != 3 or min(n) < 1:
            raise ValueError(f"shape must be three counts >= 1, got {shape!r}")
        axes = [o[:, k, None] + np.arange(n[k]) * h[k] for k in range(3)]
        with np.errstate(all="ignore"):
            out = np.broadcast_to(_grid(self, axes), (*n, len(o)))  # (a, b, c, n) inside
        out = np.ascontiguousarray(np.moveaxis(out, -1, 0), dtype=np.float64)
        return out[0] if single else out

    def evaluate_lines(
        self, origin: Any, step: Any, ijk: np.ndarray, axis: np.ndarray, t: np.ndarray
    ) -> np.ndarray:
        """Values at ``origin + (ijk + t e_axis) * step``: points on the lines of a lattice
        (integer ``ijk (n, 3)``, ``axis (n,)`` in 0..2, ``t (n,)``), such as a mesher's
        vertices on its cells' edges. The same values as :meth:`evaluate` (to rounding);
        a separable field takes what depends on the lattice's coordinates from tables."""
        lines = _sdf().Lines(
            origin, step, np.asarray(ijk), np.asarray(axis), np.asarray(t, dtype=np.float64)
        )
        with np.errstate(all="ignore"):
            out = np.broadcast_to(_grid(self, lines), (len(lines),))
        return np.ascontiguousarray(out, dtype=np.float64)

    @functools.cached_property
    def _cache(self) -> dict[str, Any]:
        """Acceleration structures built on first use (k-d trees, winding-number trees)."""
        return {}

    # ------------------------------------------------------------------ value protocol

    def fingerprint(self) -> Any:
        return {
            "op": self.op,
            "args": {k: _fingerprint(v) for k, v in sorted(self.args.items())},
            "children": [c.fingerprint() for c in self.children],
            "bounds": None if self.bounds is None else self.bounds.tolist(),
            "lipschitz": self.lipschitz,
        }

    @property
    def nbytes(self) -> int:
        own = sum(
            v.nbytes if isinstance(v, (np.ndarray, Geometry)) else 64 for v in self.args.values()
        )
        return 256 + own + sum(c.nbytes for c in self.children)

    def __repr__(self) -> str:
        return f"Field({self.op}{', bounded' if self.bounds is not None else ''})"

    def display_mesh(self) -> Any:
        """A preview Mesh: the zero set at 1/64 of the bounds' largest side; an unbounded
        TPMS in a cube of two periods; None for other unbounded fields."""
        from ..kernels.field.mesher import mesh_field
        from .mesh import Mesh

        field = self
        if self.bounds is None and self.op == "tpms":
            side = 2.0 * self.args["period"]
            field = Field.intersection([self, Field.box([side] * 3, [side / 2] * 3)])
        if field.bounds is None:
            return None
        lo, hi = field.bounds
        cell = float((hi - lo).max()) / 64 or 1.0
        grid = field.evaluate_grid if field.separable else None
        lines = field.evaluate_lines if field.separable else None
        v, t = mesh_field(field.evaluate, lo, hi, cell, field.lipschitz, grid=grid, lines=lines)
        return Mesh(v, t.reshape(-1), np.arange(0, 3 * len(t) + 1, 3))

    def to_pyvista(self) -> Any:
        """The preview mesh (:meth:`display_mesh`) as pyvista PolyData."""
        preview = self.display_mesh()
        if preview is None:
            raise ValueError("an unbounded field has no shape to show; mesh it with bounds")
        return preview.to_pyvista()

    # ------------------------------------------------------------------ constructors

    @classmethod
    def sphere(cls, radius: float, center: Any = (0, 0, 0)) -> Field:
        c = np.asarray(center, float)
        return cls("sphere", {"radius": float(radius), "center": c}, (), [c - radius, c + radius])

    @classmethod
    def box(cls, size: Any, center: Any = (0, 0, 0), radius: float = 0.0) -> Field:
        s, c = np.asarray(size, float), np.asarray(center, float)
        args = {"size": s, "center": c, "radius": float(radius)}
        return cls("box", args, (), [c - s / 2, c + s / 2])

    @classmethod
    def cylinder(cls, radius: float, height: float, center: Any = (0, 0, 0)) -> Field:
        c = np.asarray(center, float)
        h = np.array([radius, radius, height / 2])
        args = {"radius": float(radius), "height": float(height), "center": c}
        return cls("cylinder", args, (), [c - h, c + h])

    @classmethod
    def torus(cls, major: float, minor: float, center: Any = (0, 0, 0)) -> Field:
        c = np.asarray(center, float)
        h = np.array([major + minor, major + minor, minor])
        args = {"major": float(major), "minor": float(minor), "center": c}
        return cls("torus", args, (), [c - h, c + h])

    @classmethod
    def tpms(cls, kind: str, period: float, thickness: float) -> Field:
        # f / |grad f| is a distance to first order only: culling with twice the reach
        args = {"kind": str(kind), "period": float(period), "thickness": float(thickness)}
        return cls("tpms", args, (), None, lipschitz=2.0)

    @classmethod
    def expression(
        cls, value: Callable[..., Any], bounds: Any = None, lipschitz: float = 1.0
    ) -> Field:
        return cls("expression", {"value": value}, (), bounds, lipschitz)

    @classmethod
    def union(cls, fields: list[Field], smooth: float = 0.0) -> Field:
        box = _grow(_box_union([f.bounds for f in fields]), max(smooth, 0) / 4)
        lip = max(f.lipschitz for f in fields)
        return cls("union", {"smooth": float(smooth)}, tuple(fields), box, lip)

    @classmethod
    def intersection(cls, fields: list[Field], smooth: float = 0.0) -> Field:
        box = _box_intersection([f.bounds for f in fields])
        lip = max(f.lipschitz for f in fields)
        return cls("intersection", {"smooth": float(smooth)}, tuple(fields), box, lip)

    @classmethod
    def difference(cls, a: Field, b: Field, smooth: float = 0.0) -> Field:
        lip = max(a.lipschitz, b.lipschitz)
        return cls("difference", {"smooth": float(smooth)}, (a, b), a.bounds, lip)

    @classmethod
    def shell(cls, field: Field, thickness: float) -> Field:
        box = _grow(field.bounds, thickness / 2)
        return cls("shell", {"thickness": float(thickness)}, (field,), box, field.lipschitz)

    @classmethod
    def offset(cls, field: Field, distance: float) -> Field:
        box = _grow(field.bounds, max(distance, 0.0))
        return cls("offset", {"distance": float(distance)}, (field,), box, field.lipschitz)

    @classmethod
    def transform(cls, field: Field, matrix: Any, translate: Any, scale: Any) -> Field:
        """``x -> R (s * x) + t`` applied to the shape (R a rotation matrix, s > 0 per axis).

        A uniform scale keeps a distance a distance (times s); a non-uniform one gives a
        value scaled by the smallest factor, a bound whose gradient may reach
        ``max(s) / min(s)`` (the ``lipschitz`` the mesher then culls with).
        """
        r, t = np.asarray(matrix, float), np.asarray(translate, float)
        s = np.broadcast_to(np.asarray(scale, float), (3,)).copy()
        box = None
        if field.bounds is not None:
            corners = np.array(np.meshgrid(*field.bounds.T, indexing="ij")).reshape(3, -1).T
            moved = (corners * s) @ r.T + t
            box = [moved.min(0), moved.max(0)]
        args = {"matrix": r, "translate": t, "scale": s}
        lip = field.lipschitz * float(s.max() / s.min())
        return cls("transform", args, (field,), box, lip)

    @classmethod
    def from_mesh(cls, mesh: Geometry) -> Field:
        b = mesh.bounds  # type: ignore[attr-defined]
        return cls("from_mesh", {"mesh": mesh}, (), b)

    @classmethod
    def from_curves(cls, curves: list[Geometry], polylines: np.ndarray, radius: float) -> Field:
        """Tubes of ``radius`` round ``polylines`` (segments (m, 2, 3)) drawn from ``curves``."""
        seg = np.asarray(polylines, float)
        box = [seg.reshape(-1, 3).min(0) - radius, seg.reshape(-1, 3).max(0) + radius]
        args = {"curves": list(curves), "segments": seg, "radius": float(radius)}
        return cls("from_curves", args, (), box)


class _FrozenDict(dict):
    """A dict nobody can change (the field's parameters)."""

    def _refuse(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("a Field's parameters are read-only")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse  # type: ignore


def _fingerprint(v: Any) -> Any:
    if isinstance(v, Geometry):
        return {"type": type(v).__name__, "state": v.fingerprint()}
    if isinstance(v, list):
        return [_fingerprint(x) for x in v]
    if isinstance(v, np.ndarray):
        return v
    if callable(v):
        return _expression_fingerprint(v)
    return v


# ---------------------------------------------------------------------- the operations


def _sdf():
    from ..kernels.field import sdf

    return sdf


def _blend(field: Field, p: np.ndarray, pick: str) -> np.ndarray:
    sdf = _sdf()
    k = field.args["smooth"]
    values = [c.evaluate(p) for c in field.children]
    out = values[0]
    for v in values[1:]:
        out = sdf.smooth_min(out, v, k) if pick == "min" else sdf.smooth_max(out, v, k)
    return out


def _difference(field: Field, p: np.ndarray) -> np.ndarray:
    a, b = field.children
    return _sdf().smooth_max(a.evaluate(p), -b.evaluate(p), field.args["smooth"])


def _transform(field: Field, p: np.ndarray) -> np.ndarray:
    a = field.args
    local = (p - a["translate"]) @ a["matrix"] / a["scale"]  # R^T (p - t) / s, row-wise
    return field.children[0].evaluate(local) * float(a["scale"].min())


def _expression(field: Field, p: np.ndarray) -> np.ndarray:
    out = np.asarray(field.args["value"](x=p[:, 0], y=p[:, 1], z=p[:, 2]), dtype=np.float64)
    out = np.broadcast_to(out, (len(p),))
    if not np.isfinite(out).all():
        i = int(np.argmax(~np.isfinite(out)))
        text = getattr(field.args["value"], "text", "the expression")
        raise ValueError(f"{text!r} is not finite at {p[i].tolist()}")
    return out


def _from_mesh(field: Field, p: np.ndarray) -> np.ndarray:
    from ..kernels.geometry import meshdist

    cache = field._cache
    if "signed" not in cache:
        mesh = field.args["mesh"]
        tri, _ = meshdist.fan_triangles(mesh.face_indices, mesh.face_offsets)
        cache["signed"] = meshdist.SignedDistance(mesh.vertices, tri)
    return cache["signed"](p)


def _from_curves(field: Field, p: np.ndarray) -> np.ndarray:
    from ..kernels.geometry import meshdist

    cache = field._cache
    if "nearest" not in cache:
        cache["nearest"] = meshdist.Nearest(field.args["segments"])
    return cache["nearest"].distance(p) - field.args["radius"]


def _points_grid(field: Field, at: Any) -> np.ndarray:
    """The point-wise fallback of :meth:`Field.evaluate_grid` and :meth:`evaluate_lines`."""
    if isinstance(at, _sdf().Lines):
        return field.evaluate(np.stack(at.columns(), axis=1))
    x, y, z = np.broadcast_arrays(  # (a, b, c, n), as the tables' lattices are
        at[0].T[:, None, None, :], at[1].T[None, :, None, :], at[2].T[None, None, :, :]
    )
    p = np.stack([x.reshape(-1), y.reshape(-1), z.reshape(-1)], axis=1)
    return field.evaluate(p).reshape(x.shape)


def _grid(field: Field, at: Any) -> np.ndarray:
    """``field`` on a lattice (``at``: its three axes) or on lines of one (``at``: Lines)."""
    op = _GRID.get(field.op)
    return _points_grid(field, at) if op is None else op(field, at)


def _blend_grid(field: Field, at: Any, pick: str) -> np.ndarray:
    sdf = _sdf()
    k = field.args["smooth"]
    values = [_grid(c, at) for c in field.children]
    out = values[0]
    for v in values[1:]:
        out = sdf.smooth_min(out, v, k) if pick == "min" else sdf.smooth_max(out, v, k)
    return out


def _transform_grid(field: Field, at: Any) -> np.ndarray:
    a = field.args
    if not np.array_equal(a["matrix"], np.eye(3)):  # a rotation mixes the axes
        return _points_grid(field, at)
    if isinstance(at, _sdf().Lines):
        local = at.moved(a["translate"], a["scale"])
    else:
        local = [(x - t) / s for x, t, s in zip(at, a["translate"], a["scale"], strict=True)]
    return _grid(field.children[0], local) * float(a["scale"].min())


def _leaf(name: str, *params: str) -> Callable[[Field, Any], np.ndarray]:
    """A primitive on a lattice (``<name>_grid``) or on its lines (``<name>_lines``)."""

    def run(field: Field, at: Any) -> np.ndarray:
        sdf = _sdf()
        kernel = getattr(sdf, f"{name}_lines" if isinstance(at, sdf.Lines) else f"{name}_grid")
        return kernel(at, *(field.args[p] for p in params))

    return run


_GRID: dict[str, Callable[[Field, Any], np.ndarray]] = {
    "sphere": _leaf("sphere", "radius", "center"),
    "box": _leaf("box", "size", "center", "radius"),
    "tpms": _leaf("tpms", "kind", "period", "thickness"),
    "union": lambda f, g: _blend_grid(f, g, "min"),
    "intersection": lambda f, g: _blend_grid(f, g, "max"),
    "difference": lambda f, g: _sdf().smooth_max(
        _grid(f.children[0], g), -_grid(f.children[1], g), f.args["smooth"]
    ),
    "shell": lambda f, g: np.abs(_grid(f.children[0], g)) - f.args["thickness"] / 2.0,
    "offset": lambda f, g: _grid(f.children[0], g) - f.args["distance"],
    "transform": _transform_grid,
}

_OPS: dict[str, Callable[[Field, np.ndarray], np.ndarray]] = {
    "sphere": lambda f, p: _sdf().sphere(p, f.args["radius"], f.args["center"]),
    "box": lambda f, p: _sdf().box(p, f.args["size"], f.args["center"], f.args["radius"]),
    "cylinder": lambda f, p: _sdf().cylinder(
        p, f.args["radius"], f.args["height"], f.args["center"]
    ),
    "torus": lambda f, p: _sdf().torus(p, f.args["major"], f.args["minor"], f.args["center"]),
    "tpms": lambda f, p: _sdf().tpms(p, f.args["kind"], f.args["period"], f.args["thickness"]),
    "expression": _expression,
    "union": lambda f, p: _blend(f, p, "min"),
    "intersection": lambda f, p: _blend(f, p, "max"),
    "difference": _difference,
    "shell": lambda f, p: np.abs(f.children[0].evaluate(p)) - f.args["thickness"] / 2.0,
    "offset": lambda f, p: f.children[0].evaluate(p) - f.args["distance"],
    "transform": _transform,
    "from_mesh": _from_mesh,
    "from_curves": _from_curves,
}
