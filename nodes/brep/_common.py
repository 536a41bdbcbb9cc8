"""What the ``brep.*`` nodes share: the install check, the solid of a recipe, failures made
input errors, the regions of curves as faces, and the per-element edge and face selectors.

OpenCASCADE is imported only inside the functions here (and the node functions), never when
the node modules are: ``import formgraph`` registers the nodes without it, and a graph using
them without it fails at check time with :func:`requires`'s sentence.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from formgraph.core.errors import InputError
from formgraph.core.registry import Context
from formgraph.geometry import Curve, NurbsCurve, Solid
from formgraph.kernels import brep as kbrep
from formgraph.language.elements import ElementValue

__all__ = ["call", "nurbs_of", "regions", "requires", "select", "solid"]


def requires() -> str | None:
    """None when OpenCASCADE is installed, else how to install it (the check's sentence)."""
    return kbrep.missing()


def call(port: str, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """``fn(*args)``, a :class:`~formgraph.kernels.brep.BrepError` made an error on the
    input it names (else on ``port``)."""
    from formgraph.kernels.brep import occ

    try:
        return fn(*args, **kwargs)
    except kbrep.BrepError as exc:
        raise InputError(exc.port or port, str(exc)) from None
    except occ.FAILURES:  # a failure no kernel foresaw: said as ours, not as OCC's text
        raise InputError(
            port, "OpenCASCADE could not compute this from the input (a degenerate shape?)"
        ) from None


def solid(shape: Any, op: str, **args: Any) -> Solid:
    """The Solid of an OCC shape made by ``op`` from ``args`` (its recipe)."""
    from formgraph.geometry.solid import recipe_key

    return Solid.of(shape, recipe_key(op, **args))


def nurbs_of(curves: list[Curve], port: str, what: str = "curve") -> list[tuple]:
    """The (control points, degree, knots, weights) of each curve, which must be NURBS:
    only they go to a solid exactly."""
    out = []
    for k, c in enumerate(curves):
        if not isinstance(c, NurbsCurve):
            raise InputError(
                port,
                f"{what} {k} is a {type(c).__name__}; exact solids are bounded by NURBS curves "
                "(make it one with nurbs.interpolate through its points)",
            )
        out.append((c.control_points, c.degree, c.knots, c.weights if c.rational else None))
    return out


def regions(
    curves: list[Curve], port: str, tolerance: float | None, ctx: Context
) -> list[tuple[tuple, list[tuple]]]:
    """The even-odd region of closed curves in the XY plane (as ``curves.boolean`` reads
    them), as its parts: an outer outline (counter-clockwise) and its holes (clockwise),
    each an exact NURBS curve where the input was (:mod:`formgraph.nodes._outlines`)."""
    from formgraph.kernels.curves import regions as kregions
    from formgraph.nodes import _outlines

    if not curves:
        raise InputError(port, "no curves: give the closed outlines of a region")
    nurbs_of(curves, port)
    tol = _outlines.sampling_tolerance(tolerance, curves, port)
    rings, sampled, sources = _outlines.sample_rings(curves, port, tol, ctx)
    region = _outlines.make_region(kregions.even_odd_region, rings, port)
    outlines = _outlines.outline_curves(region, curves, sampled, sources, tol, ctx)
    if not outlines:
        raise InputError(port, "the curves bound no area (their even-odd region is empty)")
    _, _, hole = kregions.rings_of(region)
    parts: list[tuple[tuple, list[tuple]]] = []
    for c, is_hole in zip(nurbs_of(outlines, port), hole.tolist(), strict=True):
        if is_hole:
            parts[-1][1].append(c)
        else:
            parts.append((c, []))
    return parts


# ------------------------------------------------------------------------------ selectors


def _env(table: Any, kinds: dict[str, float], faces: bool) -> dict[str, Any]:
    n = len(table)
    env: dict[str, Any] = {name: value for name, value in kinds.items()}
    env.update(
        x=table.centre[:, 0],
        y=table.centre[:, 1],
        z=table.centre[:, 2],
        kind=table.kind,
        i=np.arange(n, dtype=np.float64),
        count=float(n),
    )
    if faces:
        env.update(area=table.size, nx=table.normal[:, 0], ny=table.normal[:, 1])
        env["nz"] = table.normal[:, 2]
    else:
        env["length"] = table.size
    return env


def select(value: Any, table: Any, port: str, what: str, ctx: Context) -> list[int]:
    """The elements (OCC's numbers, 0-based) that ``value`` selects among the rows of
    ``table`` (edges or faces): all for None or true, none for false, else those where the
    per-element expression is true. Collapsed edges are never selected. Selecting nothing
    is a warning naming the selector."""
    from formgraph.kernels.brep.topology import KINDS

    n = len(table)
    usable = table.kind != KINDS["degenerate"]
    if value is None or value is True:
        return np.flatnonzero(usable).tolist()
    if value is False:
        ctx.warn(f"{port}: false selects none of the {n} {what}: the solid is left as it is")
        return []
    if not isinstance(value, ElementValue):
        raise InputError(port, f"expected true, false or a per-element expression, got {value!r}")
    faces = what == "faces"
    env = _env(table, KINDS, faces)
    for part in value.parts:
        names = getattr(part, "compiled", None)
        if names is None:
            continue
        unknown = sorted(names.names - set(part.params) - set(env))
        if unknown:
            size = "area, nx ny nz (the outward normal)" if faces else "length"
            kinds = " ".join(k for k in KINDS if k != "degenerate")
            raise InputError(
                port,
                f"'{value.text}' names '{unknown[0]}', which is not a param nor a name of the "
                f"{what}: x y z (the centre), {size}, kind, i, count; the kinds: {kinds}",
            )
    try:
        chosen = value.mask(env, n, what)
    except ValueError as exc:
        raise InputError(port, str(exc)) from None
    picked = np.flatnonzero(chosen & usable).tolist()
    if not picked:
        lo, hi = table.centre.min(0), table.centre.max(0)
        span = ", ".join(
            f"{a} {lo[k]:.4g}..{hi[k]:.4g}" for k, a in enumerate("xyz") if hi[k] > lo[k]
        )
        ctx.warn(
            f"{port} '{value.text}' selects none of the {n} {what} (their centres span "
            f"{span or 'one point'}): the solid is left as it is"
        )
    return picked
