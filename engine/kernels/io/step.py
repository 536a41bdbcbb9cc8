"""STEP (ISO 10303-21) files of exact NURBS geometry and faceted meshes, AP214.

What goes in (ISO 10303-42 resources, as CAD programs exchange them):

- each NURBS surface as a ``B_SPLINE_SURFACE_WITH_KNOTS`` (the complex rational entity with
  ``RATIONAL_B_SPLINE_SURFACE`` when weighted), made the face of its own open shell: an
  ``ADVANCED_FACE`` bounded by the four edges of its parameter domain, each edge the exact
  boundary curve (the control net's first or last row or column, after clamping). A side
  that collapses to a point (a pole) is left out of the loop; two sides that coincide (the
  seam of a closed surface) are one edge used twice, once each way. The open shells make
  one ``SHELL_BASED_SURFACE_MODEL``, which CAD programs show as surface bodies;
- each curve a ``B_SPLINE_CURVE_WITH_KNOTS`` (rational where weighted) in a
  ``GEOMETRIC_CURVE_SET``;
- each closed mesh a ``MANIFOLD_SOLID_BREP`` of a ``CLOSED_SHELL``, an open one an
  ``OPEN_SHELL`` of the surface model, each polygon a planar face bounded by a
  ``POLY_LOOP`` (a faceted solid);
- exact solids come as the entities of another STEP file (OpenCASCADE's, written by
  :mod:`formgraph.kernels.brep.stepwrite`: manifold solid B-reps with their own products,
  names and colours), appended with their entity numbers moved past ours (``attach``).

All hang off one product, in millimetres. Numbers are written as their shortest round-trip
decimals, in bulk (:mod:`formgraph.kernels.io.numfmt`), so the file holds the geometry to the
last bit; control points and mesh vertices are ``CARTESIAN_POINT`` rows built as arrays.
"""

from __future__ import annotations

import re

import numpy as np

from ..nurbs import clamp, clamp_surface, is_clamped
from .numfmt import float_words, format_int, join_rows, squeeze

__all__ = ["write_step"]

Curve = tuple[np.ndarray, int, np.ndarray, "np.ndarray | None"]
Surface = tuple[np.ndarray, int, int, np.ndarray, np.ndarray, "np.ndarray | None"]


class _File:
    """Entity lines, numbered as they are added."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.next = 1

    def add(self, text: str) -> int:
        k = self.next
        self.parts.append(f"#{k}={text};\n".encode())
        self.next += 1
        return k

    def points(self, xyz: np.ndarray) -> np.ndarray:
        """``CARTESIAN_POINT`` rows for every point of ``xyz`` (n, 3); their ids."""
        xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        ids = np.arange(self.next, self.next + len(xyz), dtype=np.int64)
        block = 1 << 15
        for s in range(0, len(xyz), block):
            b = xyz[s : s + block]
            cols = [_reals(b[:, c]) for c in range(3)]
            self.parts.append(
                join_rows(
                    [
                        b"#",
                        format_int(ids[s : s + block]),
                        b"=CARTESIAN_POINT('',(",
                        cols[0],
                        b",",
                        cols[1],
                        b",",
                        cols[2],
                    ],
                    b"));\n",
                )  # fmt: skip
            )
        self.next += len(xyz)
        return ids

    def data(self) -> bytes:
        return b"".join(self.parts)


def _reals(x: np.ndarray) -> np.ndarray:
    """STEP reals: the shortest round-trip text with a decimal point always (``1.``,
    ``1.5E-05``), as a NUL-padded canvas (n, w)."""
    x = np.asarray(x, dtype=np.float64) + 0.0  # -0.0 -> 0.0
    canvas = float_words(x).view(np.uint8).copy()
    # repr writes 1e-05 / 1.5e+16: STEP wants an upper-case E and a '.' in the mantissa
    is_e = canvas == ord("e")
    canvas[is_e] = ord("E")
    bare = np.flatnonzero(is_e.any(axis=1) & ~(canvas == ord(".")).any(axis=1))
    if bare.size:  # a one-digit mantissa ('1e-05'): the point goes before the E
        at = np.argmax(is_e[bare], axis=1)[:, None]
        cols = np.arange(canvas.shape[1])[None, :]
        rows = canvas[bare]
        moved = np.take_along_axis(rows, np.where(cols > at, cols - 1, cols), axis=1)
        moved[cols == at] = ord(".")
        canvas[bare] = moved
    return canvas


def _real(x: float) -> str:
    return squeeze(_reals(np.array([x]))).decode()


def _refs(ids) -> str:
    """``(#1,#2,...)``, laid out in one array operation."""
    ids = np.asarray(ids, dtype=np.int64).ravel()
    if ids.size == 0:
        return "()"
    return "(" + join_rows([b"#", format_int(ids)], b",").decode()[:-1] + ")"


def _reals_text(values) -> str:
    """``(a,b,c)`` of the values' STEP reals, formatted in one array operation."""
    x = np.ravel(np.asarray(values, dtype=np.float64))
    if x.size == 0:
        return "()"
    return "(" + join_rows([_reals(x)], b",").decode()[:-1] + ")"


def _knot_lists(knots: np.ndarray) -> tuple[str, str]:
    values, counts = np.unique(np.asarray(knots, dtype=np.float64), return_counts=True)
    return "(" + ",".join(str(int(c)) for c in counts) + ")", _reals_text(values)


def _clamp_surface(s: Surface) -> Surface:
    cp, du, dv, ku, kv, w = s
    cp2, ku2, kv2, w2 = clamp_surface(cp, du, dv, ku, kv, w)
    return cp2, du, dv, ku2, kv2, w2


def _clamp_curve(c: Curve) -> Curve:
    return c if is_clamped(c[1], c[2]) else clamp(*c)


def _curve_entity(f: _File, c: Curve, closed: bool = False) -> int:
    cp, p, k, w = _clamp_curve(c)
    return _curve_on(f, f.points(cp), p, _knot_lists(k), w, closed)


def _curve_on(
    f: _File, ids: np.ndarray, p: int, knots: tuple[str, str], w, closed: bool = False
) -> int:
    """A B-spline curve entity on existing points (``ids``) and knot lists."""
    mults, values = knots
    flag = ".T." if closed else ".F."
    if w is None or np.all(w == w[0]):
        return f.add(
            f"B_SPLINE_CURVE_WITH_KNOTS('',{p},{_refs(ids)},.UNSPECIFIED.,{flag},.F.,"
            f"{mults},{values},.UNSPECIFIED.)"
        )
    return f.add(
        f"(BOUNDED_CURVE()B_SPLINE_CURVE({p},{_refs(ids)},.UNSPECIFIED.,{flag},.F.)"
        f"B_SPLINE_CURVE_WITH_KNOTS({mults},{values},.UNSPECIFIED.)CURVE()"
        f"GEOMETRIC_REPRESENTATION_ITEM()RATIONAL_B_SPLINE_CURVE({_reals_text(w)})"
        f"REPRESENTATION_ITEM(''))"
    )


def _ref_rows(ids: np.ndarray) -> str:
    """``((#1,#2),(#3,#4))`` of a grid of ids, laid out as one canvas."""
    nu, nv = ids.shape
    digits = format_int(ids.ravel())
    w = digits.shape[1]
    cells = np.zeros((nu, nv, w + 2), dtype=np.uint8)
    cells[:, :, 0] = ord("#")
    cells[:, :, 1 : w + 1] = digits.reshape(nu, nv, w)
    cells[:, :, w + 1] = ord(",")
    rows = np.zeros((nu, nv * (w + 2) + 2), dtype=np.uint8)
    rows[:, 0] = ord("(")
    rows[:, 1:-1] = cells.reshape(nu, -1)
    rows[:, -2] = ord(")")  # the last cell's comma closes the row
    rows[:, -1] = ord(",")
    return "(" + squeeze(rows).decode()[:-1] + ")"


def _surface_face(f: _File, s: Surface) -> int:
    cp, du, dv, ku, kv, w = _clamp_surface(s)
    nu, nv = cp.shape[:2]
    ids = f.points(cp.reshape(-1, 3)).reshape(nu, nv)
    rows = _ref_rows(ids)
    mu, vu = _knot_lists(ku)
    mv, vv = _knot_lists(kv)
    if w is None or np.all(w == w.flat[0]):
        surf = f.add(
            f"B_SPLINE_SURFACE_WITH_KNOTS('',{du},{dv},{rows},.UNSPECIFIED.,.F.,.F.,.F.,"
            f"{mu},{mv},{vu},{vv},.UNSPECIFIED.)"
        )
    else:
        weights = "(" + ",".join(_reals_text(r) for r in w) + ")"
        surf = f.add(
            f"(BOUNDED_SURFACE()B_SPLINE_SURFACE({du},{dv},{rows},.UNSPECIFIED.,.F.,.F.,.F.)"
            f"B_SPLINE_SURFACE_WITH_KNOTS({mu},{mv},{vu},{vv},.UNSPECIFIED.)"
            f"GEOMETRIC_REPRESENTATION_ITEM()RATIONAL_B_SPLINE_SURFACE({weights})"
            f"REPRESENTATION_ITEM('')SURFACE())"
        )
    # the domain's four sides, counter-clockwise in (u, v): v = v0, u = u1, v = v1, u = u0
    # each side's curve stands on the net's own boundary points and the surface's knots
    wu = None if w is None else w
    side_ids = [ids[:, 0], ids[-1, :], ids[:, -1], ids[0, :]]
    sides = [
        (cp[:, 0], du, (mu, vu), None if wu is None else wu[:, 0]),
        (cp[-1, :], dv, (mv, vv), None if wu is None else wu[-1, :]),
        (cp[:, -1], du, (mu, vu), None if wu is None else wu[:, -1]),
        (cp[0, :], dv, (mv, vv), None if wu is None else wu[0, :]),
    ]
    corner_ids = [ids[0, 0], ids[-1, 0], ids[-1, -1], ids[0, -1]]
    forward = [True, True, False, False]
    corners = [cp[0, 0], cp[-1, 0], cp[-1, -1], cp[0, -1]]
    scale = float(np.abs(cp).max()) or 1.0
    vertex_ids: list[int] = []
    for c in corners:  # corners that coincide share a vertex
        for j, prev in enumerate(corners[: len(vertex_ids)]):
            if np.linalg.norm(c - prev) <= 1e-12 * scale:
                vertex_ids.append(vertex_ids[j])
                break
        else:
            vertex_ids.append(f.add(f"VERTEX_POINT('',#{corner_ids[len(vertex_ids)]})"))
    edges: list[int | None] = [None] * 4
    oriented = []
    for k, (pts, deg, kn, ww) in enumerate(sides):
        if np.all(np.linalg.norm(pts - pts[0], axis=1) <= 1e-12 * scale):
            continue  # a pole: no edge
        start, end = vertex_ids[k], vertex_ids[(k + 1) % 4]
        if not forward[k]:
            start, end = end, start
        twin = None
        if k >= 2:  # the seam of a closed surface: this side is the opposite one
            o = k - 2
            if edges[o] is not None and np.allclose(pts, sides[o][0], rtol=0, atol=1e-12 * scale):
                twin = edges[o]
        if twin is None:
            curve = _curve_on(f, side_ids[k], deg, kn, ww)
            twin = f.add(f"EDGE_CURVE('',#{start},#{end},#{curve},.T.)")
            edges[k] = twin
            same = forward[k]  # sides 2 and 3 run against their curves' parameter
        else:
            same = False  # the seam's second use runs against the first
        oriented.append(f.add(f"ORIENTED_EDGE('',*,*,#{twin},{'.T.' if same else '.F.'})"))
    loop = f.add(f"EDGE_LOOP('',{_refs(oriented)})")
    bound = f.add(f"FACE_OUTER_BOUND('',#{loop},.T.)")
    return f.add(f"ADVANCED_FACE('',(#{bound}),#{surf},.T.)")


def _rows(f: _File, parts: list, end: bytes = b");\n") -> None:
    """Entity lines laid out in bulk: ``parts`` as for :func:`join_rows`."""
    f.parts.append(join_rows(parts, end))


def _ids(f: _File, n: int) -> np.ndarray:
    out = np.arange(f.next, f.next + n, dtype=np.int64)
    f.next += n
    return out


def _mesh_faces(f: _File, v: np.ndarray, fi: np.ndarray, fo: np.ndarray) -> np.ndarray:
    """One planar face per polygon (a ``POLY_LOOP`` of the shared vertex points on its
    ``PLANE``), every entity kind laid out for all faces at once; the faces' ids."""
    pid = f.points(v)
    sizes = np.diff(fo)
    nf = sizes.size
    # Newell normals (exact for planar polygons, a best fit otherwise), all faces at once
    nxt = np.arange(fi.size) + 1
    nxt[fo[1:] - 1] = fo[:-1]
    a, b = v[fi], v[fi[nxt]]
    face_of = np.repeat(np.arange(nf), sizes)
    cross = np.stack(
        [
            (a[:, 1] - b[:, 1]) * (a[:, 2] + b[:, 2]),
            (a[:, 2] - b[:, 2]) * (a[:, 0] + b[:, 0]),
            (a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1]),
        ],
        axis=1,
    )
    n = np.stack([np.bincount(face_of, weights=cross[:, c], minlength=nf) for c in range(3)], 1)
    length = np.linalg.norm(n, axis=1)
    n = np.where(length[:, None] > 0, n / np.where(length > 0, length, 1)[:, None], [0, 0, 1])
    ref = v[fi[fo[:-1] + 1]] - v[fi[fo[:-1]]]
    ref = ref - (ref * n).sum(1)[:, None] * n
    alt = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    alt = alt - (alt * n).sum(1)[:, None] * n
    ref = np.where(np.linalg.norm(ref, axis=1)[:, None] > 1e-300, ref, alt)
    ref /= np.linalg.norm(ref, axis=1)[:, None]
    loops, bounds, axes, refs, places, planes, faces = (_ids(f, nf) for _ in range(7))
    for size in np.unique(sizes):  # POLY_LOOPs, one layout per polygon size
        k = np.flatnonzero(sizes == size)
        corner = fi[fo[k][:, None] + np.arange(size)]
        parts: list = [b"#", format_int(loops[k]), b"=POLY_LOOP('',("]
        for j in range(size):
            parts += [b"#" if j == 0 else b",#", format_int(pid[corner[:, j]])]
        _rows(f, parts, b"));\n")
    _rows(f, [b"#", format_int(bounds), b"=FACE_OUTER_BOUND('',#", format_int(loops)], b",.T.);\n")
    for ids, d in ((axes, n), (refs, ref)):
        cols = [_reals(d[:, c]) for c in range(3)]
        _rows(
            f,
            [b"#", format_int(ids), b"=DIRECTION('',(", cols[0], b",", cols[1], b",", cols[2]],
            b"));\n",
        )
    _rows(
        f,
        [b"#", format_int(places), b"=AXIS2_PLACEMENT_3D('',#", format_int(pid[fi[fo[:-1]]]),
         b",#", format_int(axes), b",#", format_int(refs)],
        b");\n",
    )  # fmt: skip
    _rows(f, [b"#", format_int(planes), b"=PLANE('',#", format_int(places)], b");\n")
    _rows(
        f,
        [b"#", format_int(faces), b"=FACE_SURFACE('',(#", format_int(bounds), b"),#",
         format_int(planes)],
        b",.T.);\n",
    )  # fmt: skip
    return faces


def write_step(
    *,
    curves: list[Curve] = (),  # type: ignore[assignment]
    surfaces: list[Surface] = (),  # type: ignore[assignment]
    meshes: list[tuple[np.ndarray, np.ndarray, np.ndarray, bool]] = (),  # type: ignore[assignment]
    name: str = "formgraph",
    attach: bytes = b"",
) -> bytes:
    """A STEP AP214 file (ISO 10303-21) of exact curves and surfaces and faceted meshes.

    Parameters
    ----------
    curves : list of (control_points (n, 3), degree, knots, weights or None)
    surfaces : list of (control_points (nu, nv, 3), degree_u, degree_v, knots_u, knots_v,
        weights (nu, nv) or None)
    meshes : list of (vertices, face_indices, face_offsets, closed)
        A closed mesh becomes a faceted solid (closed shell), an open one an open shell.
    name : str
        The product's name.
    attach : bytes
        Another STEP file whose entities (its own products) join this one's.

    Returns
    -------
    bytes
    """
    f = _File()
    app = f.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
    f.add(
        f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    )
    pctx = f.add(f"PRODUCT_CONTEXT('',#{app},'mechanical')")
    dctx = f.add(f"PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')")
    safe = name.replace("'", "''")
    prod = f.add(f"PRODUCT('{safe}','{safe}','',(#{pctx}))")
    form = f.add(f"PRODUCT_DEFINITION_FORMATION('','',#{prod})")
    pdef = f.add(f"PRODUCT_DEFINITION('design','',#{form},#{dctx})")
    pds = f.add(f"PRODUCT_DEFINITION_SHAPE('','',#{pdef})")
    mm = f.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))")
    rad = f.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))")
    sr = f.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())")
    unc = f.add(
        f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#{mm},'distance_accuracy_value','')"
    )
    ctx = f.add(
        f"(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))"
        f"GLOBAL_UNIT_ASSIGNED_CONTEXT((#{mm},#{rad},#{sr}))REPRESENTATION_CONTEXT('',''))"
    )
    (o,) = f.points(np.zeros((1, 3)))
    z = f.add("DIRECTION('',(0.,0.,1.))")
    x = f.add("DIRECTION('',(1.,0.,0.))")
    items = [f.add(f"AXIS2_PLACEMENT_3D('',#{o},#{z},#{x})")]
    shells = []
    for s in surfaces:
        face = _surface_face(f, s)
        shells.append(f.add(f"OPEN_SHELL('',(#{face}))"))
    for v, fi, fo, closed in meshes:
        faces = _mesh_faces(
            f, np.asarray(v, float), np.asarray(fi, np.int64), np.asarray(fo, np.int64)
        )
        if closed:
            shell = f.add(f"CLOSED_SHELL('',{_refs(faces)})")
            items.append(f.add(f"MANIFOLD_SOLID_BREP('',#{shell})"))
        else:
            shells.append(f.add(f"OPEN_SHELL('',{_refs(faces)})"))
    if shells:
        items.append(f.add(f"SHELL_BASED_SURFACE_MODEL('',{_refs(shells)})"))
    if len(curves):
        ids = [_curve_entity(f, c) for c in curves]
        items.append(f.add(f"GEOMETRIC_CURVE_SET('',{_refs(ids)})"))
    rep = f.add(f"SHAPE_REPRESENTATION('{safe}',{_refs(items)},#{ctx})")
    f.add(f"SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})")
    header = (
        "ISO-10303-21;\nHEADER;\n"
        "FILE_DESCRIPTION(('formgraph model'),'2;1');\n"
        f"FILE_NAME('{safe}.stp','1970-01-01T00:00:00',(''),(''),'formgraph','formgraph','');\n"
        "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
    ).encode()
    return header + f.data() + _renumbered(attach, f.next - 1) + b"ENDSEC;\nEND-ISO-10303-21;\n"


_TOKEN = re.compile(rb"'(?:[^']|'')*'|#(\d+)")


def _renumbered(data: bytes, offset: int) -> bytes:
    """The entities of the DATA section of STEP file ``data``, every ``#n`` (outside
    strings) made ``#(n + offset)``."""
    if not data:
        return b""
    start = data.index(b"DATA;") + len(b"DATA;")
    end = data.rindex(b"ENDSEC;")

    def moved(m: re.Match[bytes]) -> bytes:
        return m.group(0) if m.group(1) is None else b"#%d" % (int(m.group(1)) + offset)

    return _TOKEN.sub(moved, data[start:end]).lstrip(b"\n")
