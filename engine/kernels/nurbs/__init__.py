"""NURBS kernel: the exact curves and surfaces every curve and surface node stands on.

Pure numpy array functions, vectorized over parameters, following L. Piegl and W. Tiller,
*The NURBS Book* (2nd ed., 1997); algorithm numbers are cited in each docstring. This
module gathers the family's public names; the code lives in

- ``basis``: knot spans, basis functions and their derivatives, blossoms, validation;
- ``curve``: curve points and derivatives, knot vectors, periodic curves, circles, arcs;
- ``surface``: surface points, grids, partial derivatives and normals;
- ``knots``: knot insertion and refinement, degree elevation, Bezier decomposition,
  reparametrization, compatibility;
- ``fit``: global interpolation, open and closed;
- ``construct``: loft, extrusion, revolution, rotation-minimizing frames, sweep.

Curves are ``(control_points (n, 3), degree, knots (n + degree + 1,), weights (n,) | None)``;
surfaces ``(control_points (nu, nv, 3), degree_u, degree_v, knots_u, knots_v,
weights (nu, nv) | None)`` with u along the first axis. ``weights=None`` is non-rational.
"""

from __future__ import annotations

from .banded import banded_entries
from .basis import (
    basis_function_derivatives,
    basis_functions,
    blossom_basis,
    domain_spans,
    find_spans,
    validate_curve,
    validate_surface,
)
from .construct import (
    extrude,
    loft,
    revolve,
    rotation_minimizing_frames,
    skin,
    sweep,
)
from .curve import (
    arc,
    circle,
    clamped_uniform_knots,
    curve_derivatives,
    curve_evaluate,
    evaluate_homogeneous,
    homogeneous,
    periodic_curve,
    plane_frame,
    project,
)
from .fit import fit_columns, interpolate, interpolation_parameters
from .knots import (
    clamp,
    decompose_bezier,
    decompose_bezier_batch,
    decompose_bezier_surface,
    elevate_degree,
    insert_knot,
    insert_knot_surface,
    is_clamped,
    make_compatible,
    refine_knots,
    reparametrize,
    respace,
)
from .surface import (
    basis_matrix,
    clamp_surface,
    surface_derivatives,
    surface_evaluate,
    surface_evaluate_grid,
    surface_normals,
)

__all__ = [
    "arc",
    "banded_entries",
    "basis_function_derivatives",
    "basis_functions",
    "basis_matrix",
    "blossom_basis",
    "circle",
    "clamp",
    "clamp_surface",
    "clamped_uniform_knots",
    "curve_derivatives",
    "curve_evaluate",
    "decompose_bezier",
    "decompose_bezier_batch",
    "decompose_bezier_surface",
    "domain_spans",
    "elevate_degree",
    "evaluate_homogeneous",
    "extrude",
    "find_spans",
    "fit_columns",
    "homogeneous",
    "insert_knot",
    "insert_knot_surface",
    "interpolate",
    "interpolation_parameters",
    "is_clamped",
    "loft",
    "make_compatible",
    "periodic_curve",
    "plane_frame",
    "project",
    "refine_knots",
    "reparametrize",
    "respace",
    "revolve",
    "rotation_minimizing_frames",
    "skin",
    "surface_derivatives",
    "surface_evaluate",
    "surface_evaluate_grid",
    "surface_normals",
    "sweep",
    "validate_curve",
    "validate_surface",
]
