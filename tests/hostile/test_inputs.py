"""Hostile input paths and files: escapes, FIFOs, caps, lying headers and zip bombs."""

from __future__ import annotations

import os
import threading
import zipfile
from pathlib import Path

import pytest

import formgraph as fg
from formgraph.core import safety


def _graph(folder: Path, path: str) -> Path:
    g = folder / "g.yaml"
    g.write_text(f"formgraph: 1\nnodes:\n  m: {{type: read.mesh, path: '{path}'}}\n")
    return g


@pytest.mark.parametrize(
    "path, match",
    [
        ("../outside.stl", r"leaves the inputs folder \('\.\.'\)"),
        ("/etc/passwd", "is absolute"),
        ("C:\\\\x.stl", "is absolute"),
        ("~/x.stl", "is absolute"),
        ("a/../../x.stl", "leaves the inputs folder"),
    ],
)
def test_paths_that_leave_the_folder_are_refused_at_check(tmp_path, path, match):
    with pytest.raises(fg.GraphError, match=match) as info:
        fg.load(_graph(tmp_path, path))
    assert "node 'm', input 'path'" in str(info.value)


def test_a_symlink_out_is_refused_before_anything_is_read(tmp_path):
    (tmp_path / "in").mkdir()
    (tmp_path / "secret.stl").write_bytes(b"\0" * 84)
    os.symlink(tmp_path / "secret.stl", tmp_path / "in" / "link.stl")
    with pytest.raises(fg.PathError, match="through a symlink"):
        fg.load(_graph(tmp_path / "in", "link.stl")).evaluate("m")


def test_a_symlinked_folder_out_is_refused(tmp_path):
    (tmp_path / "in").mkdir()
    (tmp_path / "elsewhere").mkdir()
    os.symlink(tmp_path / "elsewhere", tmp_path / "in" / "sub")
    (tmp_path / "elsewhere" / "x.stl").write_bytes(b"\0" * 84)
    with pytest.raises(fg.PathError, match="through a symlink"):
        fg.load(_graph(tmp_path / "in", "sub/x.stl")).evaluate("m")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_never_blocks(tmp_path):
    os.mkfifo(tmp_path / "pipe.stl")
    result: list[BaseException] = []

    def run() -> None:
        try:
            fg.load(_graph(tmp_path, "pipe.stl")).evaluate("m")
        except BaseException as exc:  # noqa: BLE001  (handed to the test thread)
            result.append(exc)

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(20)
    assert not t.is_alive(), "reading a FIFO blocked"
    assert isinstance(result[0], fg.PathError) and "not a regular file" in str(result[0])


def test_a_folder_is_not_a_file(tmp_path):
    (tmp_path / "d.stl").mkdir()
    with pytest.raises(fg.PathError, match="is a folder"):
        fg.load(_graph(tmp_path, "d.stl")).evaluate("m")


def test_read_input_caps_the_size(tmp_path):
    (tmp_path / "big.bin").write_bytes(b"x" * 1000)
    assert safety.read_input(tmp_path / "big.bin", max_bytes=1000) == b"x" * 1000
    with pytest.raises(fg.PathError, match="is larger than 999 bytes"):
        safety.read_input(tmp_path / "big.bin", max_bytes=999)


def test_a_huge_claimed_triangle_count_allocates_nothing(tmp_path):
    # 10 GB worth of triangles claimed in an 84-byte file
    (tmp_path / "lie.stl").write_bytes(b"\0" * 80 + (200_000_000).to_bytes(4, "little"))
    with pytest.raises(fg.NodeError, match="claims 200,000,000 triangles"):
        fg.load(_graph(tmp_path, "lie.stl")).evaluate("m")


def test_a_ply_claiming_a_billion_faces_allocates_nothing(tmp_path):
    (tmp_path / "lie.ply").write_bytes(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        b"property float y\nproperty float z\nelement face 1000000000\n"
        b"property list uchar int vertex_indices\nend_header\n" + b"\0" * 36 + b"\3"
    )
    with pytest.raises(fg.NodeError, match="truncated"):
        fg.load(_graph(tmp_path, "lie.ply")).evaluate("m")


def test_a_3mf_member_lying_about_its_size_stops_at_the_cap(tmp_path):
    from formgraph.kernels.io.threemf_read import read_3mf

    path = tmp_path / "bomb.3mf"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("3D/3dmodel.model", b"<model>" + b"\n" * (8 << 20) + b"</model>")
    with pytest.raises(ValueError, match="zip bomb|more than"):
        read_3mf(path.read_bytes(), max_bytes=1 << 20)


def test_a_3mf_with_a_dtd_is_refused(tmp_path):
    import io

    from formgraph.kernels.io.threemf_read import read_3mf

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr(
            "3D/3dmodel.model",
            '<?xml version="1.0"?><!DOCTYPE m [<!ENTITY a "aaaa">]><model>&a;</model>',
        )
    with pytest.raises(ValueError, match="DTD"):
        read_3mf(buf.getvalue())


def test_a_gltf_node_cycle_is_refused():
    import json

    from formgraph.kernels.io.gltf import read_gltf

    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1]}, {"children": [0]}],
    }
    with pytest.raises(ValueError, match="cycle"):
        read_gltf(json.dumps(doc).encode())


def test_a_gltf_accessor_past_its_buffer_is_refused():
    import base64
    import json

    from formgraph.kernels.io.gltf import read_gltf

    data = "data:application/octet-stream;base64," + base64.b64encode(b"\0" * 36).decode()
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": data, "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 1000, "type": "VEC3"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    }
    with pytest.raises(ValueError, match="runs past"):
        read_gltf(json.dumps(doc).encode())


LAUGHS = (
    b'<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
    + b"".join(
        f'<!ENTITY {n} "{("&" + p + ";") * 10}">'.encode()
        for p, n in zip("abcdefg", "bcdefgh", strict=True)
    )
    + b']><svg xmlns="http://www.w3.org/2000/svg"><text>&h;</text></svg>'
)
XXE = (
    b'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/hostname">]>'
    b'<svg xmlns="http://www.w3.org/2000/svg"><text>&x;</text></svg>'
)


@pytest.mark.parametrize("data", [LAUGHS, XXE], ids=["billion-laughs", "external-entity"])
def test_svg_entity_attacks_are_refused(tmp_path, data):
    (tmp_path / "a.svg").write_bytes(data)
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\nnodes:\n  c: {type: read.curves, path: a.svg}\n"
    )
    with pytest.raises(fg.NodeError, match="not an SVG document"):
        fg.load(tmp_path / "g.yaml").evaluate("c")
