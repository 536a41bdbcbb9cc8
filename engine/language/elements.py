"""Per-element expressions: an input written once and evaluated for every element.

``scale: "=0.5 + rand(i)"`` on ``mesh.copy_to_points`` reads ``i``, which is no param: the
expression is then not worked out once for the graph but handed to the node, which
evaluates it over all its points at once (one vectorized call, never a loop per point).
The names such an expression may read: ``x y z`` (the point, or the face centre), ``nx ny
nz`` (the normal, where there is one), ``i`` (the element's index), ``count`` (how many
there are), every attribute of the element by name (a vector attribute is an (n, k) array:
``=normal`` hands it over whole) and the graph's params.

:func:`reads_elements` tells the check and the runner which inputs are per-element;
:class:`ElementValue` is what the node receives; :func:`element_env` builds the names for a
point set or a mesh; :meth:`ElementValue.evaluate` checks the names against them and says
which exist when one does not.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .bound import Bound
from .model import Expr, Input, Items, Literal

__all__ = ["VARIABLES", "ElementValue", "bind_elements", "element_env", "reads_elements"]

VARIABLES = ("x", "y", "z", "nx", "ny", "nz", "i", "count")


def _exprs(value: Input) -> list[Expr]:
    if isinstance(value, Expr):
        return [value]
    if isinstance(value, Items):
        return [e for item in value.items for e in _exprs(item)]
    return []


def reads_elements(value: Input, params: Mapping[str, Any] | set[str]) -> bool:
    """Whether ``value`` holds an expression reading a name that is not a param (so it is
    evaluated per element). Wires are never per-element."""
    if isinstance(value, Items) and any(not isinstance(i, (Expr, Literal)) for i in value.items):
        return False
    return any(e.compiled.names - set(params) for e in _exprs(value))


@dataclass(frozen=True)
class ElementValue:
    """A per-element input: one expression, or a list of components (numbers or
    expressions) that makes a vector per element.

    Attributes
    ----------
    parts : tuple
        :class:`~formgraph.language.bound.Bound` expressions and plain numbers.
    vector : bool
        Whether it was written as a list (``[0, 0, "=360 * rand(i)"]``).
    """

    parts: tuple[Any, ...]
    vector: bool

    @property
    def text(self) -> str:
        texts = [f"={p.text}" if isinstance(p, Bound) else repr(p) for p in self.parts]
        return f"[{', '.join(texts)}]" if self.vector else texts[0]

    @property
    def names(self) -> set[str]:
        return {n for p in self.parts if isinstance(p, Bound) for n in p.compiled.names}

    def _check_names(self, env: Mapping[str, Any], what: str) -> None:
        """Raise ValueError naming the first name that is neither a param, a variable nor
        an attribute, with the attributes that exist."""
        for p in self.parts:
            if not isinstance(p, Bound):
                continue
            missing = sorted(p.compiled.names - set(p.params) - set(env))
            if missing:
                attrs = sorted(set(env) - set(VARIABLES))
                have = ", ".join(attrs) if attrs else "none"
                raise ValueError(
                    f"expression '={p.text}' names '{missing[0]}', which is not a param, a "
                    f"variable ({', '.join(n for n in VARIABLES if n in env)}) or an "
                    f"attribute of the {what} (attributes: {have})"
                )

    def mask(self, env: Mapping[str, Any], count: int, what: str = "elements") -> np.ndarray:
        """The value as one bool per element, ``(count,)``: the expression must give true or
        false (a comparison, combined by ``and`` / ``or`` / ``not``), not numbers.

        Raises
        ------
        ValueError
            A list of components, a name that does not exist, a result of numbers.
        """
        if self.vector:
            raise ValueError(f"{self.text} is a list; a test is one expression, e.g. '=z > 10'")
        p = self.parts[0]
        if not isinstance(p, Bound):
            return np.full(count, bool(p))
        self._check_names(env, what)
        with np.errstate(all="ignore"):
            v = np.asarray(p.compiled(p.params, **env))
        if v.dtype != np.bool_:
            kind = "numbers" if np.issubdtype(v.dtype, np.number) else f"{v.dtype} values"
            raise ValueError(
                f"'={p.text}' gives {kind}, not true or false: write a test such as "
                f"'=z > 10' or '=rand(i) < 0.5' (and, or, not combine tests)"
            )
        if v.ndim == 0:
            return np.full(count, bool(v))
        if v.shape != (count,):
            raise ValueError(f"'={p.text}' gives an array of shape {v.shape}, not one per element")
        return v

    def evaluate(self, env: Mapping[str, Any], count: int, what: str = "elements") -> np.ndarray:
        """The value for each of ``count`` elements: ``(count,)`` for one expression that
        gives a number per element, ``(count, k)`` for a vector.

        Raises
        ------
        ValueError
            A name that is neither a param, a variable nor an attribute (the message lists
            the attributes that exist); a result that is not finite or has the wrong shape.
        """
        self._check_names(env, what)
        cols = []
        for j, p in enumerate(self.parts):
            if isinstance(p, Bound):
                with np.errstate(all="ignore"):
                    v = np.asarray(p.compiled(p.params, **env), dtype=np.float64)
            else:
                v = np.asarray(p, dtype=np.float64)
            if v.ndim == 0 or (v.ndim >= 1 and v.shape[0] != count):
                if v.ndim > 1 or (v.ndim == 1 and self.vector):
                    raise ValueError(f"{self.text} gives an array of shape {v.shape}")
                v = np.broadcast_to(v, (count,) + v.shape)
            if self.vector and v.ndim != 1:
                raise ValueError(
                    f"component {j} of {self.text} gives {v.shape[1:]} values per element; "
                    f"each component must be one number per element"
                )
            cols.append(v)
        out = np.stack(cols, axis=1) if self.vector else cols[0]
        if out.ndim > 2:
            raise ValueError(f"{self.text} gives an array of shape {out.shape}")
        if not np.all(np.isfinite(out)):
            bad = int(np.argwhere(~np.isfinite(out.reshape(count, -1)))[0, 0])
            raise ValueError(f"{self.text} is not finite at element {bad}")
        return out


def bind_elements(value: Input, params: Mapping[str, Any]) -> ElementValue:
    """The :class:`ElementValue` of a per-element input, its params bound."""

    def bind(item: Input) -> Any:
        if isinstance(item, Expr):
            return Bound(item.compiled, {n: params[n] for n in item.compiled.names if n in params})
        return item.value  # type: ignore[union-attr]

    if isinstance(value, Items):
        return ElementValue(tuple(bind(i) for i in value.items), True)
    return ElementValue((bind(value),), False)


def element_env(
    geometry: Any, domain: str = "point", names: set[str] | None = None
) -> dict[str, Any]:
    """The names a per-element expression reads for the points (``domain="point"``) or
    faces (``"face"``) of a Points or a Mesh: coordinates, normals (a ``normal``
    attribute, else a mesh's vertex or face normals), index, count, attributes.

    ``names``: the names the expressions read, if known; a mesh's normals are then only
    computed when ``nx``, ``ny`` or ``nz`` is among them."""
    from ..geometry import Mesh

    want_normals = names is None or bool({"nx", "ny", "nz"} & names)
    if domain == "face":
        from ..kernels.mesh import meshops

        xyz = _face_centres(geometry)
        data = geometry.face_data
        normals = data.get("normal")
        if normals is None and want_normals:
            normals = meshops.face_normals(*geometry.arrays)
    else:
        xyz = geometry.vertices if isinstance(geometry, Mesh) else geometry.xyz
        data = geometry.point_data
        normals = data.get("normal")
        if normals is None and want_normals and isinstance(geometry, Mesh) and geometry.n_faces:
            from ..kernels.mesh.solidify import vertex_normals

            normals = vertex_normals(*geometry.arrays)
    n = len(xyz)
    env: dict[str, Any] = dict(data)  # the variables below win over a same-named attribute
    env.update(
        {
            "x": xyz[:, 0],
            "y": xyz[:, 1],
            "z": xyz[:, 2],
            "i": np.arange(n, dtype=np.float64),
            "count": float(n),
        }
    )
    if normals is not None and np.shape(normals) == (n, 3):
        env.update(nx=normals[:, 0], ny=normals[:, 1], nz=normals[:, 2])
    return env


def _face_centres(mesh: Any) -> np.ndarray:
    sizes = mesh.face_sizes
    if mesh.n_faces == 0:
        return np.zeros((0, 3))
    sums = np.add.reduceat(mesh.vertices[mesh.face_indices], mesh.face_offsets[:-1], axis=0)
    return sums / sizes[:, None]
