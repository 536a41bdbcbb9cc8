"""Hostile requests to the studio and hostile graphs opened in it: headers crafted to pass
for the studio's own, and graphs that try to write where they may not. None gets further
than it would from the command line."""

from __future__ import annotations

import pytest

from formgraph.studio.guard import Guard
from formgraph.studio.session import StudioSession

TOKEN = "Vq3m8tP0bW2kXc9LzR4sYd7GhJ1nFaEe5uTiOoKpQlM"
LOCAL = ("127.0.0.1", 8765)


@pytest.mark.parametrize(
    "host",
    [
        "127.0.0.1:8765@evil.example",  # userinfo trick
        "127.0.0.1:8765.evil.example",
        "127.0.0.1.evil.example:8765",
        "evil.example",  # no port: still not ours
        "localhost.:8765",  # the trailing-dot name is another host to a resolver
        "127.0.0.1:08765x",
        "127.0.0.1:8765:8765",
        "[127.0.0.1]:8765",
        "０.０.０.０:8765",  # full-width digits
        "127.0.0.1 :8765",
        "\x00127.0.0.1:8765",
    ],
)
def test_crafted_host_headers_are_refused(host):
    why = Guard(TOKEN).problem(host, LOCAL, None, False, TOKEN)
    assert why is not None and "Host" in why


@pytest.mark.parametrize(
    "origin",
    [
        "http://127.0.0.1:8765.evil.example",
        "http://127.0.0.1:8765@evil.example",
        "http://127.0.0.1:8766",
        "null",  # a sandboxed frame or a file:// page
        "http://127.0.0.1",
        "ws://127.0.0.1:8765",
        "",
    ],
)
def test_crafted_origins_cannot_open_the_websocket(origin):
    why = Guard(TOKEN).problem("127.0.0.1:8765", LOCAL, origin, True, TOKEN)
    assert why is not None and "Origin" in why


@pytest.mark.parametrize(
    "token",
    [TOKEN[:-1], TOKEN + "x", TOKEN.lower(), " " + TOKEN, TOKEN[:8], "undefined", "null"],
)
def test_near_tokens_are_refused(token):
    why = Guard(TOKEN).problem("127.0.0.1:8765", LOCAL, None, False, token)
    assert why is not None and "token" in why


def test_a_non_ascii_token_is_refused_not_raised():
    assert "token" in Guard(TOKEN).problem("127.0.0.1:8765", LOCAL, None, False, "tökén")


def test_an_export_path_out_of_the_output_folder_is_refused(tmp_path):
    graph = tmp_path / "g.yaml"
    graph.write_text(
        "formgraph: 1\n"
        "nodes:\n"
        "  box:\n"
        "    type: mesh.box\n"
        "  out:\n"
        "    type: export.stl\n"
        "    mesh: '@box'\n"
        "    path: ../../escaped.stl\n"
    )
    s = StudioSession(graph, out_dir=tmp_path / "out")
    opened = s.open()
    assert not opened.ok and "leaves the output directory" in opened.message
    assert not s.run().ok
    assert not (tmp_path.parent / "escaped.stl").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.yaml"]


def test_an_edit_cannot_make_run_write_elsewhere(tmp_path):
    graph = tmp_path / "g.yaml"
    good = (
        "formgraph: 1\n"
        "nodes:\n"
        "  box:\n"
        "    type: mesh.box\n"
        "  out:\n"
        "    type: export.stl\n"
        "    mesh: '@box'\n"
        "    path: box.stl\n"
    )
    graph.write_text(good)
    s = StudioSession(graph, out_dir=tmp_path / "out")
    assert s.open().ok
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "link").symlink_to(tmp_path.parent)
    assert not s.open(good.replace("box.stl", "link/escaped.stl")).ok or not s.run().ok
    assert not (tmp_path.parent / "escaped.stl").exists()


def test_a_huge_edit_is_a_problem_not_a_hang(tmp_path):
    graph = tmp_path / "g.yaml"
    graph.write_text("formgraph: 1\nnodes: {}\n")
    s = StudioSession(graph, out_dir=tmp_path / "out")
    cooked = s.open("formgraph: 1\n# " + "x" * (17 * 1024 * 1024) + "\nnodes: {}\n")
    assert not cooked.ok and "larger than 16 MiB" in cooked.message


def test_save_follows_a_symlinked_graph_file_to_its_own_folder(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (real / "g.yaml").write_text("formgraph: 1\nnodes: {}\n")
    link = tmp_path / "g.yaml"
    link.symlink_to(real / "g.yaml")
    s = StudioSession(link, out_dir=tmp_path / "out")
    s.open()
    s.save("formgraph: 1\n# saved\nnodes: {}\n")
    assert link.is_symlink() and "# saved" in (real / "g.yaml").read_text()
