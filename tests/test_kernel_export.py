"""Export kernels: every file read back by an independent library (or parser) and checked."""

from __future__ import annotations

import io
import re
import subprocess
import xml.etree.ElementTree as ET
import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tools import admesh, needs_admesh

from formgraph.kernels.io import (
    Path2D,
    drawing_bounds,
    dxf_bytes,
    fan_triangles,
    mesh_report,
    obj_bytes,
    pdf_bytes,
    ply_binary,
    stl_ascii,
    stl_ascii_chunks,
    stl_binary,
    svg_bytes,
)
from formgraph.kernels.io.numfmt import (
    float_words,
    format_e9,
    format_fixed,
    format_int,
    format_shortest,
    join_rows,
)

# --------------------------------------------------------------------------------------------
# shapes

BOX_V = np.array(
    [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [0, 0, 3], [2, 0, 3], [2, 1, 3], [0, 1, 3]],
    dtype=float,
)
BOX_Q = np.array(
    [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
)  # outward (counter-clockwise seen from outside)
BOX_FI, BOX_FO = BOX_Q.ravel(), np.arange(0, 25, 4)
S = np.sqrt(0.5)


def lines(canvas: np.ndarray) -> list[str]:
    return join_rows([canvas], b"\n").decode().split("\n")[:-1]


def write(tmp_path, name: str, data: bytes):
    p = tmp_path / name
    p.write_bytes(data)
    return p


# --------------------------------------------------------------------------------------------
# number formatting


SPECIAL = [
    0.0,
    -0.0,
    0.1,
    0.3,
    1 / 3,
    1.0,
    -2.0,
    10.0,
    1e15,
    1e16,
    1e17,
    123456789012345678.0,
    2.0**53,
    2.0**53 + 2,
    2.0**63,
    1e-4,
    1e-5,
    9.5e-5,
    5e-324,
    2.2250738585072014e-308,
    1.7976931348623157e308,
    1e22,
    1e23,
    0.30000000000000004,
    9007199254740993.0,
]


def test_shortest_is_repr_on_special_values():
    assert lines(format_shortest(np.array(SPECIAL))) == [repr(float(x)) for x in SPECIAL]


def test_shortest_is_repr_on_random_bit_patterns():
    rng = np.random.default_rng(7)
    x = np.frombuffer(rng.bytes(8 * 20000), dtype=np.float64)
    x = np.concatenate([x[np.isfinite(x)], rng.normal(size=5000), rng.integers(-99, 99, 500) / 8])
    assert lines(format_shortest(x)) == [repr(float(v)) for v in x]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=20))
def test_shortest_is_repr_hypothesis(values):
    assert lines(format_shortest(np.array(values))) == [repr(float(v)) for v in values]


def test_e9_reads_back_as_the_same_float32():
    rng = np.random.default_rng(3)
    x = np.concatenate(
        [
            rng.normal(size=3000) * 10.0 ** rng.integers(-40, 38, 3000),
            [0.0, -0.0, 1.0, 1e-45, 3.4028235e38],
        ]
    ).astype(np.float32)
    text = lines(format_e9(x))
    assert {len(t) for t in text} == {16}
    assert all(re.fullmatch(r" [ -]\d\.\d{8}e[+-]\d\d", t) for t in text)
    assert np.array_equal(np.array([np.float32(float(t)) for t in text]), x)


def test_fixed_and_int():
    x = np.array([1.5, -0.25, 3.0, 0.0, -1e-9, 123.4567894, 1e-6, -7.0, 12345678.1234567])
    assert lines(format_fixed(x, 6)) == [
        "1.5",
        "-0.25",
        "3",
        "0",
        "0",
        "123.456789",
        "0.000001",
        "-7",
        "12345678.123457",
    ]
    v = np.array([0, 1, 9, 10, 99, 100, 12345678, 123456789, 10**15 - 1])
    assert lines(format_int(v)) == [str(i) for i in v]
    with pytest.raises(ValueError, match="finite"):
        format_shortest(np.array([1.0, np.nan]))
    with pytest.raises(ValueError, match="below 1e15"):
        format_fixed(np.array([1e16]))


def test_lead_and_three_digit_exponents_fit():
    x = np.array([-1.2345678901234567e-300, -1.2345678901234567e300, -0.00012345678901234567])
    text = join_rows([float_words(x, lead=b" ").view(np.uint8)], b"|").decode()
    assert text.split("|")[:-1] == [" " + repr(float(v)) for v in x]


# --------------------------------------------------------------------------------------------
# STL


def test_fan_triangles_counts_and_winding():
    fi = np.arange(3 + 4 + 5 + 6)
    fo = np.array([0, 3, 7, 12, 18])
    tris = fan_triangles(fi, fo)
    assert len(tris) == 1 + 2 + 3 + 4
    assert tris[1:3].tolist() == [[3, 4, 5], [3, 5, 6]]


def _outward(normals: np.ndarray, vectors: np.ndarray, centre: np.ndarray) -> bool:
    return bool(np.all(np.einsum("ij,ij->i", normals, vectors.mean(axis=1) - centre) > 0))


def test_binary_stl_read_by_numpy_stl_and_trimesh(tmp_path):
    import trimesh
    from stl import mesh as stl_mesh

    data = stl_binary(BOX_V, BOX_FI, BOX_FO)
    assert len(data) == 84 + 50 * 12 and data[:5] != b"solid"
    m = stl_mesh.Mesh.from_file(str(write(tmp_path, "box.stl", data)), calculate_normals=False)
    assert len(m.vectors) == 12
    assert np.array_equal(m.vectors, BOX_V.astype(np.float32)[fan_triangles(BOX_FI, BOX_FO)])
    assert np.allclose(np.linalg.norm(m.normals, axis=1), 1.0)
    assert _outward(m.normals, m.vectors, np.array([1.0, 0.5, 1.5]))
    assert np.allclose(m.min_, [0, 0, 0]) and np.allclose(m.max_, [2, 1, 3])
    t = trimesh.load(io.BytesIO(data), file_type="stl")
    assert t.is_watertight and t.is_winding_consistent
    assert t.volume == pytest.approx(6.0)  # positive: wound outward


def test_ascii_stl_holds_the_binary_values(tmp_path):
    import trimesh
    from stl import mesh as stl_mesh

    rng = np.random.default_rng(1)
    v = BOX_V + rng.normal(scale=0.01, size=BOX_V.shape)
    text = stl_ascii(v, BOX_FI, BOX_FO, name="box")
    assert text.startswith(b"solid box\n") and text.endswith(b"endsolid box\n")
    assert text.count(b"facet normal") == 12 and text.count(b"endfacet") == 12
    a = stl_mesh.Mesh.from_file(str(write(tmp_path, "a.stl", text)), calculate_normals=False)
    b = stl_mesh.Mesh.from_file(
        str(write(tmp_path, "b.stl", stl_binary(v, BOX_FI, BOX_FO))), calculate_normals=False
    )
    assert np.array_equal(a.vectors, b.vectors)
    assert np.array_equal(a.normals, b.normals)
    t = trimesh.load(io.BytesIO(text), file_type="stl")
    assert len(t.faces) == 12 and t.is_watertight and t.volume > 0


def test_ascii_stl_in_blocks_is_the_same_file(monkeypatch):
    # Pieces of at most a block of facets each, joined: the whole text, byte for byte.
    from formgraph.kernels.io import exporters

    monkeypatch.setattr(exporters, "_BLOCK", 5)
    rng = np.random.default_rng(2)
    v = BOX_V + rng.normal(scale=0.01, size=BOX_V.shape)
    pieces = list(stl_ascii_chunks(v, BOX_FI, BOX_FO, name="box"))
    assert len(pieces) == 2 + 3  # solid, 12 facets in blocks of 5, endsolid
    facet = len(pieces[1]) // 5
    assert [len(p) for p in pieces[1:-1]] == [5 * facet, 5 * facet, 2 * facet]
    whole = b"".join(pieces)
    assert whole == stl_ascii(v, BOX_FI, BOX_FO, name="box")
    assert whole.count(b"endfacet") == 12
    with pytest.raises(ValueError, match="printable ASCII"):
        stl_ascii_chunks(v, BOX_FI, BOX_FO, name="a\nb")  # refused before the first piece


@needs_admesh
@pytest.mark.parametrize("writer", [stl_binary, stl_ascii])
def test_admesh_finds_nothing_to_fix(tmp_path, writer):
    path = write(tmp_path, "box.stl", writer(BOX_V, BOX_FI, BOX_FO))
    report = admesh(path)

    def stat(name: str) -> float:
        return report[name]

    assert stat("Number of facets") == 12
    for name in (
        "Degenerate facets",
        "Edges fixed",
        "Facets reversed",
        "Backwards edges",
        "Normals fixed",
        "Facets added",
        "Facets removed",
    ):
        assert stat(name) == 0, name
    assert stat("Number of parts") == 1
    assert stat("Volume") == pytest.approx(6.0)
    assert (
        "Max Z =  3.000000"
        in subprocess.run(["admesh", str(path)], capture_output=True, text=True).stdout
    )


@needs_admesh
def test_admesh_sees_a_hole_and_a_flipped_face(tmp_path):
    q = BOX_Q[:5].copy()
    q[0] = q[0][::-1]
    path = write(tmp_path, "bad.stl", stl_binary(BOX_V, q.ravel(), np.arange(0, 21, 4)))
    report = admesh(path)
    assert report["open"] == 4
    assert report["Normals fixed"] > 0


def test_mesh_report_closed_open_flipped_nonmanifold():
    r = mesh_report(BOX_V, BOX_FI, BOX_FO)
    assert (r.n_faces, r.n_triangles, r.n_edges) == (6, 12, 12)
    assert r.watertight and r.consistently_oriented and r.volume == pytest.approx(6.0)
    assert r.warnings() == []
    open_box = mesh_report(BOX_V, BOX_Q[1:].ravel(), np.arange(0, 21, 4))
    assert open_box.boundary_edges == 4 and not open_box.watertight
    assert "not watertight: 4 boundary edges" in open_box.warnings()[0]
    q = BOX_Q.copy()
    q[0] = q[0][::-1]
    flipped = mesh_report(BOX_V, q.ravel(), BOX_FO)
    assert flipped.misoriented_edges == 4 and not flipped.consistently_oriented
    inside_out = mesh_report(BOX_V, BOX_Q[:, ::-1].ravel(), BOX_FO)
    assert inside_out.volume == pytest.approx(-6.0)
    assert any("inside out" in w for w in inside_out.warnings())
    fins = np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]])  # three faces on edge 0-1
    assert mesh_report(BOX_V, fins.ravel(), np.arange(0, 10, 3)).nonmanifold_edges == 1
    degenerate = mesh_report(BOX_V, np.array([0, 1, 1]), np.array([0, 3]))
    assert degenerate.degenerate_triangles == 1


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros((3, 2)), [0, 1, 2], [0, 3]), r"\(n, 3\) array, got shape \(3, 2\)"),
        ((BOX_V, [0, 1, 9], [0, 3]), "face index 9 is out of range for 8 vertices"),
        ((BOX_V, [0, 1, 2, 3], [0, 2, 4]), "at least 3 vertices, face 0 has 2"),
        ((BOX_V, [0, 1, 2], [0, 2]), "must start at 0 and end at len"),
        ((BOX_V * np.nan, [0, 1, 2], [0, 3]), "finite"),
    ],
)
def test_bad_meshes_are_refused(args, match):
    with pytest.raises(ValueError, match=match):
        stl_binary(*args)


# --------------------------------------------------------------------------------------------
# OBJ and PLY


def test_obj_keeps_quads_and_exact_coordinates(tmp_path):
    import meshio
    import trimesh

    v = BOX_V + np.random.default_rng(2).normal(size=BOX_V.shape)
    data = obj_bytes(v, BOX_FI, BOX_FO)
    assert data.count(b"\nf ") == 6 and b"\nf 1 4 3 2\n" in data
    m = meshio.read(write(tmp_path, "box.obj", data))
    assert [(c.type, len(c.data)) for c in m.cells] == [("quad", 6)]
    assert np.array_equal(m.points, v) and np.array_equal(m.cells[0].data, BOX_Q)
    t = trimesh.load(io.BytesIO(data), file_type="obj", process=False)
    assert np.array_equal(t.vertices, v) and len(t.faces) == 12


def test_obj_mixed_faces_and_normals():
    import trimesh

    fi = np.r_[0, 3, 2, 1, 4, 5, 6, 4, 6, 7]
    fo = np.r_[0, 4, 7, 10]
    n = BOX_V / np.maximum(np.linalg.norm(BOX_V, axis=1), 1)[:, None]
    data = obj_bytes(BOX_V, fi, fo, normals=n)
    assert data.splitlines()[-3:] == [
        b"f 1//1 4//4 3//3 2//2",
        b"f 5//5 6//6 7//7",
        b"f 5//5 7//7 8//8",
    ]
    assert data.count(b"\nvn ") == 8
    t = trimesh.load(io.BytesIO(data), file_type="obj", process=False)
    assert len(t.faces) == 4
    with pytest.raises(ValueError, match="one per vertex"):
        obj_bytes(BOX_V, fi, fo, normals=n[:3])


def test_ply_read_by_trimesh_and_meshio(tmp_path):
    import meshio
    import trimesh

    data = ply_binary(BOX_V, BOX_FI, BOX_FO)
    assert data.startswith(b"ply\nformat binary_little_endian 1.0\n")
    t = trimesh.load(io.BytesIO(data), file_type="ply", process=False)
    assert np.array_equal(t.vertices, BOX_V) and t.volume == pytest.approx(6.0)
    fi = np.r_[0, 3, 2, 1, 4, 5, 6, 4, 6, 7]
    fo = np.r_[0, 4, 7, 10]
    m = meshio.read(write(tmp_path, "mixed.ply", ply_binary(BOX_V, fi, fo)))
    assert [(c.type, c.data.tolist()) for c in m.cells] == [
        ("quad", [[0, 3, 2, 1]]),
        ("triangle", [[4, 5, 6], [4, 6, 7]]),
    ]


# --------------------------------------------------------------------------------------------
# SVG and PDF

CIRCLE = Path2D(
    "arc",
    np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]]) * 10
    + [5, 5],
    closed=True,
)
SQUARE = Path2D("polyline", [[0, 0], [20, 0], [20, 20], [0, 20]], closed=True)
WAVE = Path2D("cubic", [[0, 0], [5, 10], [15, -10], [20, 0], [25, 10], [30, 5], [30, 0]])


def _svg_paths(data: bytes):
    root = ET.fromstring(data)
    ns = {"s": "http://www.w3.org/2000/svg"}
    return root, [p.get("d") for p in root.findall(".//s:path", ns)]


def _tokens(d: str) -> list:
    return [
        t if t.isalpha() else float(t) for t in re.findall(r"[A-Za-z]|-?[\d.]+(?:e[-+]?\d+)?", d)
    ]


def test_svg_paths_parse_back_to_the_points():
    rng = np.random.default_rng(5)
    wiggle = Path2D("polyline", rng.normal(size=(50, 2)) * 7)
    root, ds = _svg_paths(svg_bytes([wiggle, WAVE, SQUARE], margin=2.0))
    t = _tokens(ds[0])
    assert t[0] == "M" and t[3] == "L"
    pts = np.array([x for x in t if not isinstance(x, str)]).reshape(-1, 2)
    assert np.allclose(pts * [1, -1], wiggle.points, atol=5e-7)
    t = _tokens(ds[1])
    assert t[0] == "M" and t[3] == "C"
    pts = np.array([x for x in t if not isinstance(x, str)]).reshape(-1, 2)
    assert np.allclose(pts * [1, -1], WAVE.points)
    assert _tokens(ds[2])[-1] == "Z"
    lo, hi = drawing_bounds([wiggle, WAVE, SQUARE])
    vb = [float(x) for x in root.get("viewBox").split()]
    assert vb == pytest.approx(
        [lo[0] - 2, -hi[1] - 2, hi[0] - lo[0] + 4, hi[1] - lo[1] + 4], abs=1e-6
    )
    assert root.get("width") == f"{vb[2]:g}mm".replace("e", "e") or root.get("width").endswith("mm")
    assert float(root.get("width")[:-2]) == pytest.approx(vb[2])


def test_svg_arcs_are_exact_circle_commands():
    root, (d,) = _svg_paths(svg_bytes([CIRCLE], margin=0))
    t = _tokens(d)
    assert t[:3] == ["M", 15.0, -5.0] and t[3] == "A" and t[-1] == "Z"
    args = np.array(t[4:-1], dtype=float).reshape(4, 7)
    assert np.allclose(args[:, :2], 10.0) and np.all(args[:, 2:4] == 0)
    assert np.all(args[:, 4] == 0)  # counter-clockwise in the model: y flipped, negative angle
    assert np.allclose(args[:, 5:], [[5, -15], [-5, -5], [5, 5], [15, -5]])
    assert [float(x) for x in root.get("viewBox").split()] == [-5, -15, 20, 20]
    cw = Path2D("arc", CIRCLE.points[::-1])
    _, (d2,) = _svg_paths(svg_bytes([cw]))
    assert np.all(np.array(_tokens(d2)[4:], dtype=float).reshape(4, 7)[:, 4] == 1)


def test_cubic_bounds_are_tight():
    lo, hi = drawing_bounds([Path2D("cubic", [[0, 0], [5, 10], [15, -10], [20, 0]])])
    assert hi[1] == pytest.approx(10 * np.sqrt(3) / 6) and lo[1] == pytest.approx(-hi[1])


def test_path_checks():
    with pytest.raises(ValueError, match="3k\\+1 points"):
        Path2D("cubic", np.zeros((5, 2)))
    with pytest.raises(ValueError, match="not circular"):
        Path2D("arc", [[0, 0], [1, 0], [1, 3]])
    with pytest.raises(ValueError, match="one of polyline, cubic, arc"):
        Path2D("spline", np.zeros((4, 2)))
    with pytest.raises(ValueError, match="at least one path"):
        svg_bytes([])


def _pdf_objects(data: bytes) -> dict[int, bytes]:
    start = int(re.search(rb"startxref\n(\d+)\n%%EOF\n$", data).group(1))
    assert data[start:].startswith(b"xref\n")
    m = re.match(rb"xref\n0 (\d+)\n", data[start:])
    count = int(m.group(1))
    entries = data[start + m.end() : start + m.end() + 20 * count]
    assert entries[:20] == b"0000000000 65535 f\r\n"
    objects = {}
    for i in range(1, count):
        entry = entries[20 * i : 20 * i + 20]
        assert re.fullmatch(rb"\d{10} 00000 n\r\n", entry)
        offset = int(entry[:10])
        assert data[offset:].startswith(f"{i} 0 obj\n".encode()), i
        objects[i] = data[offset : data.index(b"endobj", offset)]
    return objects


@pytest.mark.parametrize("compress", [True, False])
def test_pdf_structure_and_coordinates(compress):
    data = pdf_bytes([SQUARE, WAVE, CIRCLE], margin=1.0, compress=compress)
    assert data.startswith(b"%PDF-1.4\n")
    objs = _pdf_objects(data)
    mb = re.search(rb"/MediaBox \[0 0 ([\d.]+) ([\d.]+)\]", objs[3])
    pt = 72 / 25.4
    lo, hi = drawing_bounds([SQUARE, WAVE, CIRCLE])
    assert float(mb.group(1)) == pytest.approx((hi[0] - lo[0] + 2) * pt, abs=1e-4)
    assert float(mb.group(2)) == pytest.approx((hi[1] - lo[1] + 2) * pt, abs=1e-4)
    body = objs[4]
    length = int(re.search(rb"/Length (\d+)", body).group(1))
    stream = body[body.index(b"stream\n") + 7 :]
    raw = stream[:length]
    assert stream[length:].startswith(b"\nendstream")
    content = (zlib.decompress(raw) if compress else raw).decode()
    ops = content.split("S\n")
    assert len(ops) == 4 and ops[0].split("\n")[1].endswith(" m")
    square = [ln.split() for ln in ops[0].split("\n")[1:] if ln.strip() not in ("", "h")]
    pts = np.array([[float(a), float(b)] for a, b, _ in square]) / pt + (lo - 1)
    assert np.allclose(pts, SQUARE.points, atol=1e-4) and "h" in ops[0]
    wave = [float(x) for x in re.findall(r"-?[\d.]+", ops[1].replace(" m", "").replace(" c", ""))]
    assert np.allclose(np.array(wave).reshape(-1, 2) / pt + (lo - 1), WAVE.points, atol=1e-4)
    # the circle's cubics stay on the circle
    nums = np.array([float(x) for x in re.findall(r"-?[\d.]+", ops[2])]).reshape(-1, 2)
    ctrl = np.concatenate([nums[:1], nums[1:]]) / pt + (lo - 1)
    segs = np.stack([ctrl[0:-1:3], ctrl[1::3], ctrl[2::3], ctrl[3::3]], axis=1)
    t = np.linspace(0, 1, 33)[:, None, None]
    b = (
        (1 - t) ** 3 * segs[:, 0]
        + 3 * (1 - t) ** 2 * t * segs[:, 1]
        + 3 * (1 - t) * t**2 * segs[:, 2]
        + t**3 * segs[:, 3]
    )
    assert np.abs(np.linalg.norm(b - [5, 5], axis=-1) - 10).max() < 1e-4


# --------------------------------------------------------------------------------------------
# DXF

CIRCLE_CP = np.array(
    [
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [-1, 1, 0],
        [-1, 0, 0],
        [-1, -1, 0],
        [0, -1, 0],
        [1, -1, 0],
        [1, 0, 0],
    ],
    dtype=float,
) * 3.0 + [1, 2, 0]
CIRCLE_W = np.array([1, S, 1, S, 1, S, 1, S, 1])
CIRCLE_KNOTS = np.array([0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1])


def _read_dxf(data: bytes):
    import ezdxf

    doc = ezdxf.read(io.StringIO(data.decode("utf-8")))
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes, (auditor.errors, auditor.fixes)
    return doc


def test_dxf_spline_is_the_exact_circle():
    helix = np.column_stack([np.cos(np.arange(7)), np.sin(np.arange(7)), np.arange(7.0)])
    knots = np.r_[0, 0, 0, 0, np.arange(1, 4), 4, 4, 4, 4] / 4
    data = dxf_bytes(splines=[(CIRCLE_CP, 2, CIRCLE_KNOTS, CIRCLE_W), (helix, 3, knots, None)])
    doc = _read_dxf(data)
    circle, cubic = doc.modelspace().query("SPLINE")
    assert circle.dxf.degree == 2 and cubic.dxf.degree == 3
    assert np.array_equal(np.array(circle.control_points), CIRCLE_CP)
    assert np.array_equal(np.array(circle.knots), CIRCLE_KNOTS)
    assert np.array_equal(np.array(circle.weights), CIRCLE_W)
    pts = np.array(list(circle.construction_tool().points(np.linspace(0, 1, 2001))))
    assert np.abs(np.linalg.norm(pts - [1, 2, 0], axis=1) - 3.0).max() < 1e-9
    assert len(cubic.weights) == 0 and np.array_equal(np.array(cubic.control_points), helix)


def test_dxf_polylines_and_meshes():
    fi = np.r_[0, 3, 2, 1, 4, 5, 6, 4, 6, 7]
    fo = np.r_[0, 4, 7, 10]
    flat = np.array([[0, 0, 0], [4, 0, 0], [4, 3, 0]], dtype=float)
    data = dxf_bytes(polylines=[(flat, True), (BOX_V[4:], False)], meshes=[(BOX_V, fi, fo)])
    doc = _read_dxf(data)
    msp = doc.modelspace()
    assert [e.dxftype() for e in msp] == ["LWPOLYLINE", "POLYLINE", "MESH"]
    lw = msp.query("LWPOLYLINE")[0]
    assert lw.closed and np.array_equal(np.array(lw.get_points("xy")), flat[:, :2])
    poly = msp.query("POLYLINE")[0]
    assert poly.is_3d_polyline and not poly.is_closed
    assert np.array_equal(np.array([v.dxf.location for v in poly.vertices]), BOX_V[4:])
    mesh = msp.query("MESH")[0]
    assert np.array_equal(np.array(mesh.vertices), BOX_V)
    assert [list(f) for f in mesh.faces] == [[0, 3, 2, 1], [4, 5, 6], [4, 6, 7]]
    assert doc.header["$INSUNITS"] == 4
    assert data == dxf_bytes(
        polylines=[(flat, True), (BOX_V[4:], False)], meshes=[(BOX_V, fi, fo)]
    )  # same drawing, same bytes


@pytest.mark.parametrize(
    ("spline", "match"),
    [
        ((CIRCLE_CP, 2, CIRCLE_KNOTS[:-1], CIRCLE_W), "need 12 knots, got 11"),
        ((CIRCLE_CP, 2, CIRCLE_KNOTS[::-1], CIRCLE_W), "knots must not decrease"),
        ((CIRCLE_CP, 2, CIRCLE_KNOTS, -CIRCLE_W), "positive weights"),
        ((CIRCLE_CP, 12, CIRCLE_KNOTS, None), "degree 1 to 11"),
    ],
)
def test_dxf_bad_splines(spline, match):
    with pytest.raises(ValueError, match=match):
        dxf_bytes(splines=[spline])


# --------------------------------------------------------------------------------------------
# random meshes and drawings


@st.composite
def polygon_meshes(draw):
    n = draw(st.integers(3, 30))
    sizes = draw(st.lists(st.integers(3, 7), min_size=1, max_size=12))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 4)
    fi = rng.integers(0, n, size=sum(sizes))
    return v, fi, np.concatenate([[0], np.cumsum(sizes)])


@settings(max_examples=30, deadline=None)
@given(polygon_meshes())
def test_random_polygon_meshes_round_trip(tmp_path_factory, mesh):
    import meshio
    from stl import mesh as stl_mesh

    v, fi, fo = mesh
    tmp = tmp_path_factory.mktemp("m")
    tris = fan_triangles(fi, fo)
    assert len(tris) == int(np.sum(np.diff(fo) - 2))
    s = stl_mesh.Mesh.from_file(
        str(write(tmp, "m.stl", stl_binary(v, fi, fo))), calculate_normals=False
    )
    assert np.array_equal(s.vectors, v.astype(np.float32)[tris])
    # OBJ: every face line and every coordinate back exactly
    text = obj_bytes(v, fi, fo).decode().splitlines()
    verts = np.array([[float(x) for x in ln.split()[1:]] for ln in text if ln.startswith("v ")])
    faces = [[int(x) - 1 for x in ln.split()[1:]] for ln in text if ln.startswith("f ")]
    assert np.array_equal(verts, v)
    assert faces == [fi[a:b].tolist() for a, b in zip(fo[:-1], fo[1:], strict=True)]
    # PLY: meshio groups the faces by size; each group is the faces of that size, in order
    m = meshio.read(write(tmp, "m.ply", ply_binary(v, fi, fo)))
    assert np.array_equal(m.points, v)
    got = sorted(tuple(f) for c in m.cells for f in c.data.tolist())
    want = sorted(tuple(fi[a:b].tolist()) for a, b in zip(fo[:-1], fo[1:], strict=True))
    assert got == want


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 40), st.integers(0, 2**32 - 1), st.booleans())
def test_random_polylines_in_svg_and_pdf(n, seed, closed):
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(n, 2)) * 10.0 ** rng.integers(-1, 3)
    path = Path2D("polyline", pts, closed=closed)
    _, (d,) = _svg_paths(svg_bytes([path]))
    back = np.array([x for x in _tokens(d) if not isinstance(x, str)]).reshape(-1, 2)
    assert np.allclose(back * [1, -1], pts, atol=5.1e-7, rtol=0)
    objs = _pdf_objects(pdf_bytes([path], compress=False))
    body = objs[4]
    content = body[body.index(b"stream\n") + 7 : body.index(b"\nendstream")].decode()
    nums = [float(x) for ln in content.splitlines()[1:] for x in ln.split()[:2]
            if ln.endswith((" m", " l"))]  # fmt: skip
    lo, _ = drawing_bounds([path])
    assert np.allclose(np.array(nums).reshape(-1, 2) * 25.4 / 72 + lo - 1, pts, atol=2e-5)


def test_empty_mesh_writes_empty_files():
    v, fi, fo = np.zeros((0, 3)), np.zeros(0, dtype=int), np.zeros(1, dtype=int)
    assert stl_binary(v, fi, fo) == b"formgraph binary STL".ljust(80, b"\0") + b"\0\0\0\0"
    assert stl_ascii(v, fi, fo) == b"solid formgraph\nendsolid formgraph\n"
    assert obj_bytes(v, fi, fo) == b"# formgraph\n"
    assert b"element face 0\n" in ply_binary(v, fi, fo)
    r = mesh_report(v, fi, fo)
    assert (r.n_edges, r.n_triangles, r.watertight) == (0, 0, True)
    tri = mesh_report(np.eye(3), np.arange(3), np.array([0, 3]))
    assert (tri.n_edges, tri.boundary_edges) == (3, 3)
