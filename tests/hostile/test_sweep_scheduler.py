"""sweep --scheduler at something that is not a Dask scheduler: a sentence within the
handshake's time limit, never a hang or an allocation the peer chose."""

from __future__ import annotations

import socket
import struct
import threading
import time

import pytest

import formgraph as fg
from formgraph.cli import main as cli
from formgraph.sweeps import cluster
from formgraph.sweeps.api import sweep

GRAPH = "formgraph: 1\nparams:\n  r: 1.0\nnodes:\n  c: {type: nurbs.circle, radius: '=r'}\n"


class _Peer:
    """A loopback server that accepts and then answers with ``reply`` (None: silence)."""

    def __init__(self, reply: bytes | None):
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.reply = reply
        self.conns: list[socket.socket] = []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        self.server.settimeout(30)
        try:
            while True:
                conn, _ = self.server.accept()
                self.conns.append(conn)  # kept open: a silent peer holds the line
                if self.reply is not None:
                    conn.sendall(self.reply)
        except OSError:
            return

    def close(self) -> None:
        self.server.close()
        for c in self.conns:
            c.close()


@pytest.fixture
def peer(request, monkeypatch):
    # A silent peer is waited out for 1 s, not the default 10; a peer that answers keeps the
    # default, so a loaded machine that is slow to run its thread never turns its answer
    # into silence (the message would then name the wrong limit).
    if not request.param:
        monkeypatch.setattr(cluster, "HANDSHAKE_SECONDS", 1.0)
    p = _Peer(request.param)
    yield p
    p.close()


JUNK = struct.pack("<Q", 3 * 2**60) + b"\x00" * 64  # asks for 3 EiB
NOT_DASK = struct.pack("<Q", 16) + b"GET / HTTP/1.1\r\n"


@pytest.mark.parametrize(
    ("peer", "message"),
    [
        (None, "sent no Dask handshake within 1 s"),
        (JUNK, "is not a Dask scheduler (it announced a first message of"),
        (NOT_DASK, "is not a Dask scheduler"),
        (b"", "is not a Dask scheduler"),  # accepts, says nothing, stays open: silent too
    ],
    indirect=["peer"],
)
def test_a_peer_that_is_not_a_scheduler_is_refused_in_time(tmp_path, peer, message):
    import distributed  # noqa: F401  (imported first: a cold import on a busy machine is seconds)

    g = fg.Graph.from_text(GRAPH, file="g.yaml")
    t0 = time.monotonic()
    with pytest.raises(cluster.SweepError) as info:
        sweep(g, {"r": "1,2"}, client=f"tcp://127.0.0.1:{peer.port}", cache_dir=None)
    # the message says which limit ended it (the 1 s handshake, or the greeting read);
    # the clock only tells a refusal from a hang (distributed waits without a limit), so
    # its bound is far above any load the machine may be under
    assert time.monotonic() - t0 < 30
    text = str(info.value)
    assert (message in text) or (peer.reply == b"" and "no Dask handshake" in text), text


@pytest.mark.parametrize("peer", [JUNK], indirect=True)
def test_the_cli_says_it_in_one_line(tmp_path, peer, capsys):
    (tmp_path / "g.yaml").write_text(GRAPH)
    address = f"tcp://127.0.0.1:{peer.port}"
    out = str(tmp_path / "out")  # not ./out: the checkout is shared by the test workers
    code = cli.main(
        ["sweep", str(tmp_path / "g.yaml"), "--vary", "r=1,2", "--scheduler", address, "--out", out]
    )
    err = capsys.readouterr().err
    assert code == 1 and "not a Dask scheduler" in err and "MemoryError" not in err
    assert "internal error" not in err and len(err.strip().splitlines()) == 1


def test_nobody_listening_is_a_sentence():
    # bound and never listening: the port refuses connections and stays ours, where a port
    # closed before the probe could be taken by another process in between
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        with pytest.raises(cluster.SweepError, match="cannot reach the Dask scheduler"):
            cluster.probe_scheduler(f"tcp://127.0.0.1:{port}", timeout=1)


@pytest.mark.parametrize("command", ["sweep", "optimize"])
def test_an_unreachable_scheduler_leaves_no_file(tmp_path, capsys, command):
    # the scheduler is checked before sweep.csv, trials.csv or the journal is written: a
    # failed start leaves no table of no rows behind (it was a header-only sweep.csv)
    (tmp_path / "g.yaml").write_text(GRAPH + "  m: {type: curves.measure, curve: '@c'}\n")
    out = tmp_path / "out"
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        address = f"tcp://127.0.0.1:{s.getsockname()[1]}"
        args = ["--vary", "r=1,2"] if command == "sweep" else ["--vary", "r=1:2"]
        if command == "optimize":
            args += ["--minimize", "m.length", "--budget", "2"]
        code = cli.main(
            [command, str(tmp_path / "g.yaml"), *args, "--scheduler", address, "--out", str(out)]
        )
    err = capsys.readouterr().err
    assert code == 1 and "cannot reach the Dask scheduler" in err
    assert not out.exists()
