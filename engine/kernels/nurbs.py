"""NURBS kernel: the exact curves and surfaces every curve and surface node stands on.

Pure numpy array functions, vectorized over parameters, following L. Piegl and W. Tiller,
*The NURBS Book* (2nd ed., 1997); algorithm numbers are cited in each docstring. This
module gathers the family's public names; the code lives in ``nurbs_basis`` (spans, basis
functions, validation), ``nurbs_curve`` (curve evaluation, circles, arcs) and
``nurbs_surface`` (surface evaluation and normals).

Curves are ``(control_points (n, 3), degree, knots (n + degree + 1,), weights (n,) | None)``;
surfaces ``(control_points (nu, nv, 3), degree_u, degree_v, knots_u, knots_v,
weights (nu, nv) | None)`` with u along the first axis.
"""

from __future__ import annotations

from .nurbs_basis import (
    basis_function_derivatives,
    basis_functions,
    blossom_basis,
    domain_spans,
    find_spans,
    validate_curve,
    validate_surface,
)
from .nurbs_curve import (
    arc,
    circle,
    clamped_uniform_knots,
    curve_derivatives,
    curve_evaluate,
    homogeneous,
    periodic_curve,
    plane_frame,
    project,
)
from .nurbs_surface import (
    basis_matrix,
    surface_derivatives,
    surface_evaluate,
    surface_evaluate_grid,
    surface_normals,
)

__all__ = [
    "arc",
    "basis_function_derivatives",
    "basis_functions",
    "basis_matrix",
    "blossom_basis",
    "circle",
    "clamped_uniform_knots",
    "curve_derivatives",
    "curve_evaluate",
    "domain_spans",
    "find_spans",
    "homogeneous",
    "periodic_curve",
    "plane_frame",
    "project",
    "surface_derivatives",
    "surface_evaluate",
    "surface_evaluate_grid",
    "surface_normals",
    "validate_curve",
    "validate_surface",
]
