"""Hostile files for the readers (#33): a few kilobytes that hung a parser, decompressed
giants, fan-outs of instances, lying headers. Each parse runs in a forked child under a
time limit and a memory limit, so a regression fails the test instead of hanging (or
swapping) the suite; on the fixed code each is well under a second or two."""

from __future__ import annotations

import io
import multiprocessing
import resource
import struct
import zipfile

import numpy as np
import pytest

from formgraph.kernels.io.threemf import write_3mf
from formgraph.kernels.io.threemf_read import read_3mf

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
PROD = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"


def bounded(fn, *args, seconds: float = 20, memory: int = 2 << 30, **kwargs):
    """``fn(*args, **kwargs)`` in a forked child with ``seconds`` to finish and ``memory``
    bytes more address space than the parent has: ``('ok', result)`` or ``('error', type
    name, message)``. A child still running at the limit is killed and the test fails."""
    ctx = multiprocessing.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)

    def child() -> None:
        with open("/proc/self/status") as fh:
            size = next(int(x.split()[1]) * 1024 for x in fh if x.startswith("VmSize"))
        resource.setrlimit(resource.RLIMIT_AS, (size + memory, size + memory))
        try:
            out = ("ok", fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001  (what it raised is the answer)
            out = ("error", type(exc).__name__, str(exc))
        send.send(out)

    proc = ctx.Process(target=child, daemon=True)
    proc.start()
    try:
        if not receive.poll(seconds):
            pytest.fail(f"{getattr(fn, '__name__', fn)} still running after {seconds} s")
        return receive.recv()
    finally:
        proc.kill()
        proc.join()


def refused(fn, *args, match: str, **kwargs) -> str:
    """Assert ``fn`` raised a ValueError whose message matches ``match`` (in bounds)."""
    got = bounded(fn, *args, **kwargs)
    assert got[0] == "error" and got[1] == "ValueError", got[:3]
    import re

    assert re.search(match, got[2]), got[2]
    return got[2]


def package(model: bytes | str, extra: dict | None = None) -> bytes:
    """A 3MF zip holding ``model`` as its root part (and ``extra`` parts)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("3D/3dmodel.model", model)
        for name, data in (extra or {}).items():
            z.writestr(name, data)
    return buf.getvalue()


def model(resources: str, build: str, head: str = "") -> str:
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xmlns="{CORE}" '
        f'xmlns:p="{PROD}"{head}><resources>{resources}</resources><build>{build}</build>'
        "</model>"
    )


TRIANGLE = (
    '<object id="1" type="model"><mesh><vertices><vertex x="0" y="0" z="0"/>'
    '<vertex x="1" y="0" z="0"/><vertex x="0" y="1" z="0"/></vertices>'
    '<triangles><triangle v1="0" v2="1" v3="2"/></triangles></mesh></object>'
)


# ------------------------------------------------------------------------- 3MF: item 1


@pytest.mark.parametrize("tag", ['<object id="1">', "<m:colorgroup>", "<vertices>"])
def test_a_3mf_of_150000_unclosed_tags_is_refused_at_once(tag):
    """4.8 KB of zip: the regular expressions took past 60 s; expat reads it once."""
    data = package(f'<model xmlns="{CORE}" xmlns:m="x"><resources>' + tag * 150_000)
    assert len(data) < 10_000
    refused(read_3mf, data, match="not well-formed XML|where the 3MF core does not put", seconds=10)


def test_a_namespaced_attribute_is_not_the_core_one():
    """``p:x`` is the production namespace's x, not the vertex's: the old attribute pattern
    took it for ``x`` and shifted the vertices."""
    body = TRIANGLE.replace('<vertex x="1"', '<vertex p:x="7" x="1"').replace(
        '<vertex x="0" y="1"', '<vertex x="0" p:y="9" y="1"'
    )
    got = read_3mf(package(model(body, '<item objectid="1"/>')))
    np.testing.assert_array_equal(got.vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_array_equal(got.triangles, [[0, 1, 2]])


def test_elements_of_other_namespaces_are_passed_over_with_their_content():
    body = TRIANGLE.replace(
        "<vertices>", '<vertices><q:vertex xmlns:q="urn:other" x="5" y="5" z="5"/>'
    ).replace(
        "</mesh>", '<b:beams xmlns:b="urn:beams"><vertex x="9" y="9" z="9"/></b:beams></mesh>'
    )
    got = read_3mf(package(model(body, '<item objectid="1"/>')))
    assert len(got.vertices) == 3 and got.vertices.max() == 1


def test_a_core_element_out_of_place_is_named():
    body = TRIANGLE.replace("<vertices>", '<vertices><triangle v1="0" v2="1" v3="2"/>')
    refused(
        read_3mf, package(model(body, '<item objectid="1"/>')), match="<triangle> inside <vertices>"
    )


def test_a_required_extension_we_do_not_read_is_refused():
    slice_ns = "http://schemas.microsoft.com/3dmanufacturing/slice/2015/07"
    head = f' xmlns:s="{slice_ns}" requiredextensions="s p"'
    refused(read_3mf, package(model(TRIANGLE, '<item objectid="1"/>', head)), match="slice/2015/07")


def test_an_index_that_is_not_whole_is_refused():
    body = TRIANGLE.replace('v3="2"', 'v3="1.5"')
    refused(read_3mf, package(model(body, '<item objectid="1"/>')), match="'1.5' is not a whole")


# ------------------------------------------------------------------------- 3MF: item 3


def _fan_out(fan: int, levels: int) -> bytes:
    """Object 1 a triangle; object k + 1 holds ``fan`` copies of object k, ``levels`` deep."""
    objs = [TRIANGLE]
    for k in range(1, levels + 1):
        comps = "".join(
            f'<component objectid="{k}" transform="1 0 0 0 1 0 0 0 1 {j} 0 0"/>' for j in range(fan)
        )
        objs.append(f'<object id="{k + 1}"><components>{comps}</components></object>')
    return package(model("".join(objs), f'<item objectid="{levels + 1}"/>'))


def test_ten_components_ten_levels_deep_are_counted_not_expanded():
    data = _fan_out(10, 10)
    assert len(data) < 2000
    message = refused(read_3mf, data, match="over the budget", seconds=10)
    assert "10,000,000,000 triangles" in message and "refused before expanding" in message


def _placed(data: bytes, levels: int) -> tuple:
    """Read a fan-out and check it in the child: placement k's triangle is the first one
    moved along x by the sum of k's decimal digits (one digit a level)."""
    got = read_3mf(data)
    k = np.arange(len(got.triangles))
    shift = sum((k // 10**d) % 10 for d in range(levels))
    first = got.vertices[got.triangles[:, 0]]
    return got.triangles.shape, got.vertices.shape, bool(np.array_equal(first[:, 0], shift))


def test_a_million_placements_are_one_copy_per_object():
    """10 x 6 levels: a million placed triangles, in budget, made by one vectorized copy
    (the old reader took 36 s and 619 MB for a million instances)."""
    status, got = bounded(_placed, _fan_out(10, 6), 6, seconds=20)
    assert status == "ok"
    assert got == ((1_000_000, 3), (3_000_000, 3), True)


def test_a_budget_bounds_placements_of_empty_objects_too():
    """Objects of empty components make no triangle, yet each placement is work."""
    objs = ['<object id="1"><components></components></object>']
    for k in range(1, 9):
        comps = f'<component objectid="{k}"/>' * 10
        objs.append(f'<object id="{k + 1}"><components>{comps}</components></object>')
    data = package(model("".join(objs), '<item objectid="9"/>'))
    refused(read_3mf, data, match="object placements", seconds=10, max_elements=1_000_000)


def test_a_cycle_of_components_is_refused():
    objs = (
        '<object id="1"><components><component objectid="2"/></components></object>'
        '<object id="2"><components><component objectid="1"/></components></object>'
    )
    refused(read_3mf, package(model(objs, '<item objectid="1"/>')), match="a cycle")


def test_200000_build_items_are_read_in_bulk():
    """Items are collected and converted a block at a time (2M took 69 s and 1.56 GB)."""
    items = '<item objectid="1" transform="1 0 0 0 1 0 0 0 1 0 0 2"/>' * 200_000

    def check(data: bytes) -> tuple:
        got = read_3mf(data)
        return got.items, len(got.triangles), bool(np.all(got.vertices[:, 2] == 2))

    assert bounded(check, package(model(TRIANGLE, items)), seconds=20) == (
        "ok",
        (200_000, 200_000, True),
    )


def test_a_build_over_the_budget_is_refused_before_it_is_placed():
    refused(
        read_3mf,
        package(model(TRIANGLE, '<item objectid="1"/>' * 1000)),
        match="places 1,000 triangles and 3,000 vertices in 1,000 object placements .* over "
        "the budget of 999",
        max_elements=999,
    )


# ------------------------------------------------------------------------- 3MF: item 4


def _lying(model_bytes: bytes, claimed: int) -> bytes:
    """A zip whose model member's headers claim ``claimed`` bytes uncompressed."""
    data = bytearray(package(model_bytes))
    for sig, at in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):  # local, central headers
        k = data.find(sig)
        struct.pack_into("<I", data, k + at, claimed)
    return bytes(data)


def test_a_model_of_spaces_stops_at_the_cap_as_it_unpacks():
    """The 1.79 MB file of 1.85 GB of spaces ran 173 s at 5.3 GB: it is now counted as it
    unpacks and refused at the cap (1 GiB by default; 4 MiB here)."""
    data = package(b"<model" + b" " * (16 << 20) + b"/>")
    refused(read_3mf, data, match="claim 16,777,224 bytes .* zip bomb", max_bytes=4 << 20)
    message = refused(read_3mf, _lying(b"<model" + b" " * (16 << 20) + b"/>", 100), match=".")
    assert "unpacks to more than" in message or "Bad CRC" in message or "cannot unpack" in message
    refused(
        read_3mf,
        _lying(b"<model" + b" " * (16 << 20) + b"/>", 100),
        match="unpacks to more than 4,194,304 bytes|cannot unpack",
        max_bytes=4 << 20,
    )


def test_the_default_cap_is_the_input_cap():
    from formgraph.core.safety import MAX_INPUT_BYTES
    from formgraph.kernels.io import threemf_read

    assert threemf_read.MAX_MODEL_BYTES == MAX_INPUT_BYTES


def test_a_3mf_dtd_and_a_billion_laughs_are_refused():
    laughs = (
        '<?xml version="1.0"?><!DOCTYPE model [<!ENTITY a "aaaaaaaaaa">'
        + "".join(
            f'<!ENTITY {n} "{("&" + p + ";") * 10}">'
            for p, n in zip("abcdefg", "bcdefgh", strict=True)
        )
        + f']><model xmlns="{CORE}"><metadata name="x">&h;</metadata></model>'
    )
    refused(read_3mf, package(laughs), match="declares a DTD or an entity")


# ------------------------------------------------------------------ 3MF: what it reads


def test_production_parts_are_read_through_p_path():
    """Bambu Studio's layout: the root model's object is components naming objects in
    other model parts; their own units apply."""
    part = (
        f'<?xml version="1.0"?><model unit="centimeter" xmlns="{CORE}"><resources>'
        f"{TRIANGLE}</resources><build/></model>"
    )
    comp = (
        '<object id="5"><components><component p:path="/3D/Objects/part.model" '
        'objectid="1" transform="1 0 0 0 1 0 0 0 1 0 0 1"/></components></object>'
    )
    data = package(model(comp, '<item objectid="5"/>'), {"3D/Objects/part.model": part})
    got = read_3mf(data)
    # the part's vertices in cm (x10), the root's translation in mm
    np.testing.assert_allclose(got.vertices, [[0, 0, 1], [10, 0, 1], [0, 10, 1]])


def test_a_p_path_inside_a_non_root_part_is_refused():
    part = (
        f'<model xmlns="{CORE}" xmlns:p="{PROD}"><resources>{TRIANGLE}<object id="2">'
        '<components><component p:path="/3D/x.model" objectid="1"/></components></object>'
        "</resources></model>"
    )
    comp = (
        '<object id="5"><components><component p:path="/3D/o.model" objectid="2"/>'
        "</components></object>"
    )
    data = package(model(comp, '<item objectid="5"/>'), {"3D/o.model": part})
    refused(read_3mf, data, match="Production extension forbids")


def test_vertex_colours_round_trip_through_our_writer():
    rng = np.random.default_rng(3)
    v = rng.random((30, 3))
    t = rng.permutation(30).reshape(10, 3)  # every vertex on a triangle
    c = np.round(rng.random((30, 4)) * 255) / 255
    got = read_3mf(write_3mf([(v, t), (v + 1, t)], vertex_colors=[c, c]))
    np.testing.assert_array_equal(got.vertices, np.concatenate([v, v + 1]))
    np.testing.assert_allclose(got.colors, np.concatenate([c, c]))


def test_base_material_colours_are_read():
    got = read_3mf(write_3mf([(np.eye(3), [[0, 1, 2]])], colors=[(1, 0, 0, 1)]))
    np.testing.assert_allclose(got.colors, [[1, 0, 0, 1]] * 3)


# ------------------------------------------------------- the same attacks through read.mesh


def _read_mesh(folder, name: str, data: bytes, budget: int | None = None):
    import formgraph as fg

    (folder / name).write_bytes(data)
    text = f"formgraph: 1\nnodes:\n  m: {{type: read.mesh, path: {name}}}\n"
    (folder / "g.yaml").write_text(text)
    g = fg.load(folder / "g.yaml", **({"budget": budget} if budget else {}))
    m = g.evaluate("m")
    return np.asarray(m.vertices), np.asarray(m.face_indices)


def test_read_mesh_refuses_unclosed_tags_at_once(tmp_path):
    data = package(f'<model xmlns="{CORE}"><resources>' + '<object id="1">' * 150_000)
    got = bounded(_read_mesh, tmp_path, "u.3mf", data, seconds=10)
    assert got[0] == "error" and got[1] == "NodeError", got
    assert (
        "'u.3mf': cannot read it as a mesh" in got[2]
        and "where the 3MF core does not put one" in got[2]
    )


def test_read_mesh_does_not_shift_vertices_by_a_namespaced_attribute(tmp_path):
    body = TRIANGLE.replace('<vertex x="1"', '<vertex p:x="7" x="1"')
    status, (v, f) = bounded(
        _read_mesh, tmp_path, "p.3mf", package(model(body, '<item objectid="1"/>'))
    )
    assert status == "ok"
    np.testing.assert_array_equal(v, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])


def test_read_mesh_counts_a_fan_out_before_expanding(tmp_path):
    got = bounded(_read_mesh, tmp_path, "f.3mf", _fan_out(10, 10), seconds=10)
    assert got[0] == "error" and "10,000,000,000 triangles" in got[2], got


def test_read_mesh_does_not_take_a_foreign_vertex_for_a_core_one(tmp_path):
    """The old element pattern took any prefix's ``vertex``: the extra one shifted every
    index after it without a word."""
    body = TRIANGLE.replace(
        "<vertices>", '<vertices><q:vertex xmlns:q="urn:other" x="5" y="5" z="5"/>'
    )
    status, (v, f) = bounded(
        _read_mesh, tmp_path, "q.3mf", package(model(body, '<item objectid="1"/>'))
    )
    assert status == "ok"
    np.testing.assert_array_equal(v, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])


# ------------------------------------------------------------------- SVG: items 2, 9, 11, 13

SVG = '<svg xmlns="http://www.w3.org/2000/svg"'


def _read_curves(folder, name: str, data: bytes):
    import formgraph as fg

    (folder / name).write_bytes(data)
    text = f"formgraph: 1\nnodes:\n  c: {{type: read.curves, path: {name}}}\n"
    (folder / "g.yaml").write_text(text)
    return [np.asarray(c.control_points) for c in fg.load(folder / "g.yaml").evaluate("c")]


def curves_refused(folder, data: bytes, match: str, name: str = "a.svg") -> str:
    got = bounded(_read_curves, folder, name, data, seconds=10)
    assert got[0] == "error" and got[1] == "NodeError", got[:2]
    import re

    assert re.search(match, got[2]), got[2]
    assert not re.search(r"\b[A-Z]\w*(Error|Exception)\b", got[2].replace("NodeError", "")), got[2]
    return got[2]


@pytest.mark.parametrize(
    "data",
    [SVG.encode() + b">" + b"<" * 200_000, b"<svg" * 16_000],
    ids=["lt-without-gt", "root-without-gt"],
)
def test_an_svg_of_unclosed_tags_is_refused_at_once(tmp_path, data):
    """58 KiB of '<' took 20 s in the depth scan (a regular expression per '<')."""
    curves_refused(tmp_path, data, "not well formed")


@pytest.mark.parametrize("width", ["nanmm", "infmm", "0mm", "1e400mm", "-5mm"])
def test_an_svg_whose_width_draws_nothing_is_refused(tmp_path, width):
    data = f'{SVG} width="{width}" height="10mm"><path d="M0 0 L5 5"/></svg>'.encode()
    curves_refused(tmp_path, data, "width .*(finite|positive)")


@pytest.mark.parametrize(
    "transform, match",
    [
        ("skewX(90)", "2.16e\\+16 mm after its transforms"),
        ("scale(1e308)", "not a finite number after its transforms"),
        ("scale(0)", "flattens it"),
        ("rotate(1e400)", "the transform attribute holds '1e400'"),
    ],
)
def test_an_svg_transform_that_overflows_or_flattens_is_refused(tmp_path, transform, match):
    data = f'{SVG}><path id="p" d="M0 1 L5 5" transform="{transform}"/></svg>'.encode()
    curves_refused(tmp_path, data, match)


@pytest.mark.parametrize(
    "d, match",
    [
        ("M 0 0 Q", "the path data 'M 0 0 Q' is not valid SVG syntax"),
        ("M0 0 A 1e-320 1e-320 0 0 0 1 1", "holds a number too small or too large"),
    ],
)
def test_an_svg_path_svgelements_fails_on_is_named_in_words(tmp_path, d, match):
    """Once "(ValueError: )" and "(ZeroDivisionError: float division by zero)"."""
    data = f'{SVG}>\n<g>\n<path d="{d}"/></g></svg>'.encode()
    message = curves_refused(tmp_path, data, match)
    assert "line 3" in message


# ------------------------------------------------------------------------ DXF: items 5, 9


def _fan_dxf(levels: int, fan: int = 10) -> bytes:
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    doc.blocks.new("L0").add_line((0, 0), (1, 0))
    for k in range(1, levels + 1):
        block = doc.blocks.new(f"L{k}")
        for j in range(fan):
            block.add_blockref(f"L{k - 1}", (j, 0))
    doc.modelspace().add_blockref(f"L{levels}", (0, 0))
    out = io.StringIO()
    doc.write(out)
    return out.getvalue().encode()


def test_an_11_level_block_fan_out_is_counted_before_expanding(tmp_path):
    """Refused only after 59 s before, saying "a MINSERT of 1 copies"."""
    message = curves_refused(
        tmp_path,
        _fan_dxf(11),
        r"the drawing's blocks expand to 211,111,111,111 entities, over the budget of "
        r"1,000,000: INSERT \w+ of block 'L11' alone makes 211,111,111,110 \(blocks inside "
        r"blocks\); refused before expanding",
        name="fan.dxf",
    )
    assert "MINSERT" not in message


def test_a_block_inserting_itself_is_refused():
    ezdxf = pytest.importorskip("ezdxf")
    from formgraph.kernels.io.dxf_read import _counted

    doc = ezdxf.new()
    a, b = doc.blocks.new("A"), doc.blocks.new("B")
    a.add_blockref("B", (0, 0))
    b.add_blockref("A", (0, 0))
    doc.modelspace().add_blockref("A", (0, 0))
    with pytest.raises(ValueError, match="block '[AB]' inserts itself"):
        _counted(doc, 1000)


def _degenerate_dxf() -> bytes:
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_arc((0, 0), 0, 0, 90, dxfattribs={"handle": "A1"})
    msp.add_arc((0, 0), -5, 0, 90, dxfattribs={"handle": "A2"})
    msp.add_circle((0, 0), 0, dxfattribs={"handle": "C1"})
    msp.add_ellipse((0, 0), major_axis=(7, 0, 0), ratio=0.5, dxfattribs={"handle": "E1"})
    msp.add_line((0, 0), (1, 1))
    out = io.StringIO()
    doc.write(out)
    text = out.getvalue()
    at = text.index("AcDbEllipse")  # a zero major axis, which ezdxf will not write itself
    text = text[:at] + text[at : at + 200].replace(" 11\n7.0", " 11\n0.0", 1) + text[at + 200 :]
    return text.encode()


def test_degenerate_dxf_entities_are_warned_about_with_their_handles(tmp_path):
    import formgraph as fg

    (tmp_path / "d.dxf").write_bytes(_degenerate_dxf())
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\nnodes:\n  c: {type: read.curves, path: d.dxf}\n"
    )
    g = fg.load(tmp_path / "g.yaml")
    with pytest.warns(fg.FormgraphWarning) as caught:
        curves = g.evaluate("c")
    assert len(curves) == 1  # the line
    text = " ".join(str(w.message) for w in caught)
    assert "ARC that draws nothing (a radius of 0; handle A1)" in text
    assert "ARC that draws nothing (a radius of -5; handle A2)" in text
    assert "CIRCLE that draws nothing (a radius of 0; handle C1)" in text
    assert "ELLIPSE(#E1) with invalid major axis" in text


# --------------------------------------------------------------- item 11: lenient reads


def _mesh_refused(folder, name: str, data: bytes, match: str) -> str:
    got = bounded(_read_mesh, folder, name, data, seconds=10)
    assert got[0] == "error" and got[1] == "NodeError", got[:3]
    import re

    assert re.search(match, got[2]), got[2]
    return got[2]


def test_gltf_float_indices_are_refused(tmp_path):
    """They were cast to integers: a face [0, 0, 0]."""
    import base64
    import json

    raw = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0], "<f4").tobytes()
    raw += np.array([0.0, 1.0, 2.0], "<f4").tobytes()
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [
            {"uri": "data:;base64," + base64.b64encode(raw).decode(), "byteLength": len(raw)}
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 12},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "SCALAR"},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    }
    _mesh_refused(
        tmp_path, "f.gltf", json.dumps(doc).encode(), "indices are float32 .* unsigned integers"
    )


def test_a_gltf_scene_placing_a_mesh_too_often_is_counted_first():
    import base64
    import json

    from formgraph.kernels.io.gltf import read_gltf

    raw = np.zeros(36, np.uint8).tobytes()
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "data:;base64," + base64.b64encode(raw).decode(), "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}] * 1000,
        "scenes": [{"nodes": list(range(1000))}],
    }
    with pytest.raises(ValueError, match="places 3,000 vertices .* refused before expanding"):
        read_gltf(json.dumps(doc).encode(), max_elements=2000)


def test_an_obj_index_that_is_not_whole_is_refused(tmp_path):
    """``f 1 2 3.5`` read as ``f 1 2 3``."""
    data = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n"
    _mesh_refused(tmp_path, "a.obj", data, r"line 4: a face's vertex '3\.5' is not an index")


def test_a_4off_divides_by_its_homogeneous_w(tmp_path):
    """Its w was dropped: Geomview's 4OFF vertices are homogeneous."""
    data = b"4OFF\n3 1 0\n0 0 0 1\n2 0 0 2\n0 4 0 2\n3 0 1 2\n"
    status, (v, f) = bounded(_read_mesh, tmp_path, "a.off", data)
    assert status == "ok"
    np.testing.assert_array_equal(v, [[0, 0, 0], [1, 0, 0], [0, 2, 0]])
    _mesh_refused(tmp_path, "b.off", data.replace(b"0 0 0 1", b"0 0 0 0"), "homogeneous w is 0")


def test_an_ascii_stl_of_binary_junk_is_refused(tmp_path):
    rng = np.random.default_rng(0)
    junk = rng.integers(0, 256, 5000, dtype=np.uint8).tobytes()
    _mesh_refused(tmp_path, "a.stl", b"solid x\nfacet\n" + junk, "holds a NUL byte")
    printable = bytes(rng.integers(33, 127, 5000, dtype=np.uint8))
    _mesh_refused(
        tmp_path, "b.stl", b"solid x\nfacet\n" + printable + b"\nendsolid", "none of its lines"
    )


def _read_points(folder, name: str, data: bytes):
    import formgraph as fg

    (folder / name).write_bytes(data)
    (folder / "g.yaml").write_text(
        f"formgraph: 1\nnodes:\n  p: {{type: read.points, path: {name}}}\n"
    )
    return np.asarray(fg.load(folder / "g.yaml").evaluate("p").positions)


def test_a_text_of_nul_bytes_is_not_read_as_no_points(tmp_path):
    got = bounded(_read_points, tmp_path, "a.txt", b"\0" * 4096)
    assert got[0] == "error" and "holds a NUL byte (at byte 0, line 1)" in got[2], got


def test_a_csv_line_of_ten_million_columns_is_refused_before_it_is_split(tmp_path):
    """It took 656 MB (and 8 s): refused from its length, in 64 MB of address space here."""
    data = b"1," * 10_000_000 + b"1\n"
    got = bounded(_read_points, tmp_path, "a.csv", data, memory=256 << 20)
    assert got[0] == "error" and "line 1 is 20,000,001 characters long" in got[2], got


def test_text_of_size_1e308_is_refused(tmp_path):
    import formgraph as fg

    g = fg.Graph.from_text(
        "formgraph: 1\nnodes:\n  t: {type: curves.text, text: HI, size: 1e308}\n"
    )
    with pytest.raises(fg.NodeError, match=r"input 'size'.*beyond 1e\+15 mm"):
        g.evaluate("t")


# ------------------------------------------------------------------ item 13: in words


@pytest.mark.parametrize(
    "exc, words",
    [
        (ValueError(), "it is malformed (the reader gave no reason)"),
        (KeyError("accessors"), "a field it needs is missing (accessors)"),
        (IndexError(), "it ends before the data it announces (truncated?)"),
        (struct.error("unpack requires a buffer of 4 bytes"), "shorter than its format says"),
        (ValueError("'use' references expand"), "'use' references expand"),
    ],
)
def test_a_reader_error_is_said_in_words(exc, words):
    from formgraph.kernels.io.readers import in_words

    said = in_words(exc)
    assert words in said and "Error" not in said


def test_a_dxf_ezdxf_cannot_read_is_said_without_an_exception_name(tmp_path):
    data = b"0\nSECTION\n2\nENTITIES\n0\nCIRCLE\n10\n0\n20\n0\n40\nabc\n0\nENDSEC\n0\nEOF\n"
    message = curves_refused(
        tmp_path, data, "not a DXF drawing ezdxf can read: Invalid tag", "j.dxf"
    )
    assert "cannot read it as a drawing" in message
