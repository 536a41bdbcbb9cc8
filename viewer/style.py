"""How each kind of geometry is drawn: colours, materials, normals, edges, back faces.

The shading is meant to be honest about the geometry, as Rhino's and Blender's viewports
are: the back of a face (its vertices run clockwise as seen) is drawn in :data:`BACK_FACE`,
one colour for every layer, so a mesh that faces inward cannot pass for a correct one;
surfaces and fine meshes are smooth-shaded, but normals are split where faces meet at more
than :data:`FEATURE_ANGLE` (a box stays a box) and those feature edges and open boundaries
are drawn as lines; the edges of every face are drawn only on a coarse mesh (at most
:data:`COARSE_FACES` faces), where each face matters, or when asked for.

pyvista is imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

__all__ = [
    "BACKGROUND",
    "BACK_FACE",
    "COARSE_FACES",
    "FEATURE_ANGLE",
    "PALETTE",
    "mix",
    "shaded",
    "style",
]

# matplotlib's tab10 without its red, which is kept for back faces (as Blender's face
# orientation overlay shows them); reads well on white and keeps neighbours apart
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
)
BACK_FACE = "#e0393e"
BACKGROUND = "white"
GRID_COLOR = "#8a8a8a"
ERROR_COLOR = "#b00020"
TEXT_COLOR = "#333333"

FEATURE_ANGLE = 30.0  # degrees between face normals above which an edge stays sharp
COARSE_FACES = 1000  # a mesh with at most this many faces is drawn with its edges

MATERIAL = dict(ambient=0.22, diffuse=0.78, specular=0.2, specular_power=24)


def mix(color: str, other: str, t: float) -> tuple[float, float, float]:
    """``color`` moved ``t`` of the way to ``other`` (RGB floats)."""
    import pyvista as pv

    a = np.array(pv.Color(color).float_rgb)
    b = np.array(pv.Color(other).float_rgb)
    return tuple(float(x) for x in (1 - t) * a + t * b)  # type: ignore[return-value]


def shaded(data: Any) -> tuple[Any, Any]:
    """A surface dataset ready for smooth shading, and its feature edges.

    Point normals are computed with the vertices split along edges sharper than
    :data:`FEATURE_ANGLE`, as vtkPolyDataNormals splits them. The faces are never reordered
    (``consistent_normals=False``): reordering would turn a face the right way round and so
    hide a wrong orientation, which the back-face colour is there to show. The lines are
    the feature edges, open boundaries and non-manifold edges of the unsplit mesh, as
    vtkFeatureEdges finds them.

    A mesh of polygons only is done here in numpy, with the same points, faces, normals
    (to float32 rounding), lines and arrays, in the same order, as the two VTK filters
    make (pyvista's ``compute_normals`` and ``extract_feature_edges``); what depends on
    the faces alone (the edges, their faces, the corners around each vertex) is kept for
    the next mesh with the same faces, so a slider step that moves the vertices only
    redoes the arithmetic. Anything else (lines, strips, degenerate faces, normals of its
    own) goes through the filters.
    """
    topology = _topology_of(data)
    if topology is None:
        return _shaded_vtk(data)
    return topology.shade(data)


def _shaded_vtk(data: Any) -> tuple[Any, Any]:
    normals = data.compute_normals(
        cell_normals=False,
        point_normals=True,
        split_vertices=True,
        feature_angle=FEATURE_ANGLE,
        consistent_normals=False,
        auto_orient_normals=False,
        non_manifold_traversal=False,
    )
    lines = data.extract_feature_edges(
        feature_angle=FEATURE_ANGLE,
        boundary_edges=True,
        non_manifold_edges=True,
        feature_edges=True,
        manifold_edges=False,
    )
    return normals, lines


# ------------------------------------------------------------------ shading in numpy

_TOPOLOGIES: list[_Topology] = []  # the last few meshes' face structure (newest last)
_KEPT = 4
# corners (face vertex entries) a mesh may have for the numpy path, whose face structure
# costs about 100 bytes a corner: larger meshes (drawn once, not stepped) go through the
# filters, as they did before
_MAX_CORNERS = 1_000_000
_LOCK = threading.Lock()


def _topology_of(data: Any) -> _Topology | None:
    """The face structure of ``data`` (made once per distinct set of faces), or None when
    the numpy path does not apply."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if not data.n_points or not data.n_cells or data.n_cells != data.GetNumberOfPolys():
        return None  # lines, vertices or strips: the filters
    pd = data.GetPointData()
    if pd.GetNormals() is not None or "Normals" in data.point_data.keys():
        return None  # normals of its own (the filter drops them): the filters
    if not (_numeric(pd) and _numeric(data.GetCellData())):
        return None  # strings or other arrays numpy does not copy: the filters
    polys = data.GetPolys()
    if polys.GetNumberOfConnectivityIds() > _MAX_CORNERS:
        return None  # (see _MAX_CORNERS)
    offsets = vtk_to_numpy(polys.GetOffsetsArray()).astype(np.int64, copy=False)
    conn = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64, copy=False)
    n = data.n_points
    with _LOCK:
        for t in reversed(_TOPOLOGIES):
            if t.matches(n, offsets, conn):
                return t if t.valid else None
    t = _Topology(n, offsets.copy(), conn.copy())
    with _LOCK:
        _TOPOLOGIES.append(t)
        del _TOPOLOGIES[:-_KEPT]
    return t if t.valid else None


class _Topology:
    """What shading a polygon mesh needs of its faces alone.

    Corners are the entries of the faces' connectivity (face ``c`` has corners
    ``offsets[c]:offsets[c + 1]``); half-edge ``h`` runs from corner ``h`` to the next corner
    of its face. Each edge has the half-edges of the faces that use it: one, an open
    boundary; two (of two faces), a manifold edge, which is smooth or sharp by the angle
    of its faces; more, non-manifold.
    """

    def __init__(self, n_points: int, offsets: np.ndarray, conn: np.ndarray):
        self.n_points, self.offsets, self.conn = n_points, offsets, conn
        sizes = np.diff(offsets)
        n_cells, n_corners = len(sizes), len(conn)
        self.cell = np.repeat(np.arange(n_cells), sizes)  # the face of each corner
        nxt = np.arange(1, n_corners + 1)
        nxt[offsets[1:][sizes > 0] - 1] = offsets[:-1][sizes > 0]
        self.next = nxt
        a, b = conn, conn[nxt]
        key = np.minimum(a, b) * n_points + np.maximum(a, b)
        order = np.argsort(key, kind="stable")  # by edge, then by face
        sk = key[order]
        first = np.r_[True, sk[1:] != sk[:-1]]
        starts = np.flatnonzero(first)
        counts = np.diff(np.r_[starts, n_corners])
        edge = np.empty(n_corners, dtype=np.int64)
        edge[order] = np.cumsum(first) - 1
        # a face with fewer than 3 corners, a vertex twice, or an edge twice is degenerate:
        # the filters' walks around such a vertex are not the edges' (the filters do it)
        twice = np.zeros(n_corners, dtype=bool)
        cells_sorted = self.cell[order]
        twice[1:] = ~first[1:] & (cells_sorted[1:] == cells_sorted[:-1])
        pairs = self.cell * n_points + conn
        self.valid = bool(
            n_cells and sizes.min() >= 3 and not twice.any() and len(np.unique(pairs)) == n_corners
        )
        if not self.valid:
            return
        # edges of two faces: h1 in the lower face, h2 in the higher (sorted by face)
        two = starts[counts == 2]
        self.h1, self.h2 = order[two], order[two + 1]
        self.pair_cells = (self.cell[self.h1], self.cell[self.h2])
        # the corners each such edge joins: at its first point and at its second
        same = conn[self.h2] == conn[self.h1]
        at_a = np.where(same, self.h2, nxt[self.h2])
        at_b = np.where(same, nxt[self.h2], self.h2)
        self.link = (np.r_[self.h1, nxt[self.h1]], np.r_[at_a, at_b])
        # the lines drawn whatever the angles: open boundaries, and each non-manifold edge
        # once (by its lowest face, as vtkFeatureEdges does)
        many = np.zeros(n_corners, dtype=bool)
        many[order[starts[counts > 2]]] = True
        self.always = np.flatnonzero((counts[edge] == 1) | many)
        self._split: tuple[Any, ...] | None = None
        # the faces of each size, and their corners' points as a (faces, size) table
        self.by_size = []
        for size in np.unique(sizes):
            cells = np.flatnonzero(sizes == size)
            table = conn[offsets[cells][:, None] + np.arange(size)]
            self.by_size.append((int(size), cells, table))

    def matches(self, n_points: int, offsets: np.ndarray, conn: np.ndarray) -> bool:
        return (
            n_points == self.n_points
            and len(conn) == len(self.conn)
            and len(offsets) == len(self.offsets)
            and np.array_equal(conn, self.conn)
            and np.array_equal(offsets, self.offsets)
        )

    # ---------------------------------------------------------------------- per mesh

    def face_normals(self, points: np.ndarray) -> np.ndarray:
        """Unit face normals (float32, as vtkPolyDataNormals keeps them); zero for a face
        of no area. Newell's normal, which for a triangle is the cross product of two
        sides and for a quad that of its diagonals, done so for each size apart."""
        n = np.empty((len(self.offsets) - 1, 3))
        for size, cells, corners in self.by_size:
            if size in (3, 4):
                p = points[corners]  # (faces, size, 3)
                if size == 3:
                    u, v = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
                else:
                    u, v = p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]
                n[cells] = _cross(u, v)
            else:  # the sum of the corners' cross products, about the first corner
                p = points[corners]
                rel = p - p[:, :1]
                n[cells] = _cross(rel, np.roll(rel, -1, axis=1)).sum(axis=1)
        length = np.sqrt(np.einsum("ij,ij->i", n, n))
        n /= np.where(length > 0, length, 1.0)[:, None]
        return n.astype(np.float32)

    def split(self, smooth: np.ndarray) -> tuple[np.ndarray, np.ndarray, Any]:
        """The split corners' point ids, each output point's input point, and the sparse
        (output point, face) incidence, for the manifold edges ``smooth`` (True: not a
        feature edge).

        Around each vertex, the faces joined across smooth manifold edges form a region;
        the region holding the vertex's lowest face keeps the vertex, each other region
        gets a copy, appended after the input points in order of vertex, then of the
        region's lowest face (vtkPolyDataNormals' numbering).
        """
        cached = self._split  # (one read: another thread may put a new one)
        if cached is not None and np.array_equal(cached[0], smooth):
            return cached[1:]
        from scipy.sparse import coo_matrix, csr_matrix
        from scipy.sparse.csgraph import connected_components

        n = len(self.conn)
        on = np.r_[smooth, smooth]
        u, v = self.link[0][on], self.link[1][on]
        graph = coo_matrix((np.ones(len(u), dtype=np.int8), (u, v)), shape=(n, n))
        count, label = connected_components(graph, directed=False)
        # each region's first corner is in its lowest face (corners run face by face)
        _, first = np.unique(label, return_index=True)
        point = self.conn[first]
        order = np.lexsort((first, point))
        sp = point[order]
        head = np.r_[True, sp[1:] != sp[:-1]]
        extra = ~head
        new = np.where(head, sp, self.n_points + np.cumsum(extra) - 1)
        ids = np.empty(count, dtype=np.int64)
        ids[order] = new
        corners = ids[label]
        source = np.r_[np.arange(self.n_points), sp[extra]]
        # (output point, face) is 1 where a corner of the face is that point: times the
        # face normals, the sums of each point's faces' normals
        shape = (len(source), len(self.offsets) - 1)
        sums = csr_matrix((np.ones(n), (corners, self.cell)), shape=shape)
        self._split = (smooth.copy(), corners, source, sums)
        return corners, source, sums

    def shade(self, data: Any) -> tuple[Any, Any]:
        import pyvista as pv

        points = np.asarray(data.points)
        p64 = points.astype(np.float64, copy=False)
        fn = self.face_normals(p64)
        c1, c2 = self.pair_cells
        f64 = fn.astype(np.float64)  # (float32 products are exact in float64)
        dot = np.einsum("ij,ij->i", f64[c1], f64[c2])
        smooth = dot > np.cos(np.radians(FEATURE_ANGLE))
        corners, source, sums = self.split(smooth)

        # point normals: the sum of the faces' normals at each (split) point, made unit
        acc = (sums @ f64).astype(np.float32)
        length = np.sqrt(np.einsum("ij,ij->i", acc, acc, dtype=np.float64))
        normals = (acc / np.where(length > 0, length, 1.0)[:, None]).astype(np.float32)

        ids = np.arange(self.n_points, dtype=pv.ID_TYPE)
        surface = pv.PolyData()
        surface.points = points[source]
        surface.faces = _cells(self.offsets, corners)
        _copy_arrays(data.GetPointData(), surface.GetPointData(), source)
        _add_array(surface.GetPointData(), "pyvistaOriginalPointIds", ids[source])
        surface.GetPointData().SetNormals(_add_array(None, "Normals", normals))
        _copy_arrays(data.GetCellData(), surface.GetCellData(), None)
        return surface, self.lines(data, points, ids, smooth)

    def lines(self, data: Any, points: np.ndarray, ids: np.ndarray, smooth: np.ndarray) -> Any:
        """The boundary, non-manifold and feature edges as line cells, their points merged
        by position in the order the edges come (vtkFeatureEdges with vtkMergePoints)."""
        import pyvista as pv

        half = np.sort(np.r_[self.always, self.h1[~smooth]])
        seq = np.column_stack([self.conn[half], self.conn[self.next[half]]]).ravel()
        lines = pv.PolyData()
        if not len(seq):  # no lines: no points (of the input's type), empty arrays
            none = np.zeros(0, dtype=np.int64)
            lines.SetPoints(_vtk_points(points[:0]))
            _copy_arrays(data.GetPointData(), lines.GetPointData(), none)
            _add_array(lines.GetPointData(), "pyvistaOriginalPointIds", ids[none])
            _copy_arrays(data.GetCellData(), lines.GetCellData(), none)
            return lines
        uniq, first, inverse = np.unique(seq, return_index=True, return_inverse=True)
        xyz = points[uniq] + 0.0  # (-0.0 and 0.0 are one position)
        _, group, ginv = np.unique(xyz, axis=0, return_index=True, return_inverse=True)
        ginv = ginv.ravel()
        earliest = np.full(len(group), len(seq), dtype=np.int64)
        np.minimum.at(earliest, ginv, first)
        rank = np.empty(len(group), dtype=np.int64)
        rank[np.argsort(earliest)] = np.arange(len(group))
        kept = seq[np.sort(earliest)]  # the point each output point is copied from
        lines.points = points[kept]
        lines.lines = _cells(np.arange(0, len(seq) + 1, 2), rank[ginv[inverse]])
        _copy_arrays(data.GetPointData(), lines.GetPointData(), kept)
        _add_array(lines.GetPointData(), "pyvistaOriginalPointIds", ids[kept])
        _copy_arrays(data.GetCellData(), lines.GetCellData(), self.cell[half])
        return lines


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (..., 3) arrays (np.cross, without its overhead)."""
    out = np.empty(np.broadcast_shapes(u.shape, v.shape))
    out[..., 0] = u[..., 1] * v[..., 2] - u[..., 2] * v[..., 1]
    out[..., 1] = u[..., 2] * v[..., 0] - u[..., 0] * v[..., 2]
    out[..., 2] = u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]
    return out


def _vtk_points(points: np.ndarray) -> Any:
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints

    out = vtkPoints()
    out.SetData(numpy_to_vtk(np.ascontiguousarray(points).reshape(-1, 3), deep=True))
    return out


def _numeric(fields: Any) -> bool:
    """Whether every array of a vtk field is a numeric one (not strings or objects)."""
    return all(fields.GetArray(i) is not None for i in range(fields.GetNumberOfArrays()))


def _add_array(fields: Any, name: str, values: np.ndarray, vtk_type: int | None = None) -> Any:
    """``values`` as a named vtk array, added to ``fields`` (unless None)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk

    arr = numpy_to_vtk(np.ascontiguousarray(values), deep=True, array_type=vtk_type)
    arr.SetName(name)
    if fields is not None:
        fields.AddArray(arr)
    return arr


def _copy_arrays(source: Any, target: Any, take: np.ndarray | None) -> None:
    """Every array of ``source`` (its rows ``take``, or all) into ``target``, with the
    attribute each one is (active scalars, texture coordinates, ...) except normals: what
    vtk's CopyAllocate with CopyData (or PassData) gives."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkDataSetAttributes

    for i in range(source.GetNumberOfArrays()):
        arr = source.GetArray(i)
        values = vtk_to_numpy(arr)
        if take is not None:
            values = values[take]
        copy = _add_array(None, arr.GetName(), values, arr.GetDataType())
        for k in range(arr.GetNumberOfComponents()):
            if arr.GetComponentName(k) is not None:
                copy.SetComponentName(k, arr.GetComponentName(k))
        index = target.AddArray(copy)
        role = source.IsArrayAnAttribute(i)
        if role >= 0 and role != vtkDataSetAttributes.NORMALS:
            target.SetActiveAttribute(index, role)


def _cells(offsets: np.ndarray, conn: np.ndarray) -> Any:
    """A vtkCellArray of these offsets and connectivity."""
    import pyvista as pv

    return pv.CellArray.from_arrays(offsets, conn)


def style(kind: str, color: str, edges: bool = False) -> dict[str, Any]:
    """add_mesh keywords for one kind of geometry drawn in ``color``."""
    if kind == "points":
        return dict(color=color, render_points_as_spheres=True, point_size=12, style="points")
    if kind == "curves":
        return dict(color=color, line_width=3.5, render_lines_as_tubes=True)
    if kind in ("surfaces", "meshes"):
        # smooth_shading=False keeps pyvista from computing normals again (with faces
        # reordered); the actor's interpolation is set to Phong by apply_material
        return dict(
            color=color,
            smooth_shading=False,
            show_edges=edges,
            edge_color=mix(color, "black", 0.5),
            line_width=1.0,
            **MATERIAL,
        )
    if kind == "features":
        return dict(color=mix(color, "black", 0.55), line_width=1.6)
    # control polygon / net: thin lines in a darker shade, with their control points
    return dict(color=mix(color, "black", 0.35), line_width=1.2, style="wireframe")


def apply_material(actor: Any, kind: str) -> None:
    """Phong interpolation over the precomputed normals, and the back-face colour."""
    if kind not in ("surfaces", "meshes"):
        return
    import pyvista as pv
    from vtkmodules.vtkRenderingCore import vtkProperty

    prop = actor.GetProperty()
    prop.SetInterpolationToPhong()
    back = vtkProperty()
    back.DeepCopy(prop)
    back.SetColor(pv.Color(BACK_FACE).float_rgb)
    back.SetEdgeColor(mix(BACK_FACE, "black", 0.5))
    back.SetSpecular(0.0)
    actor.SetBackfaceProperty(back)


def set_edges(actor: Any, visible: bool) -> None:
    """Show or hide the edges of every face of a mesh or surface actor."""
    actor.GetProperty().SetEdgeVisibility(visible)
    back = actor.GetBackfaceProperty()
    if back is not None:
        back.SetEdgeVisibility(visible)
