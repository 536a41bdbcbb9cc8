"""What a sweep prints on a terminal: Ctrl-C ends it with one line (no worker tracebacks),
and a node's warning in a worker is one line of ours, not Dask's file and source line."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]

SCRIPT = (
    "import sys\n"
    "import sweep_stubs  # noqa: F401 (stub.logged)\n"
    "from formgraph.cli.main import main\n"
    "if __name__ == '__main__':  # workers spawn and import this file again\n"
    "    sys.exit(main(sys.argv[1:]))\n"
)


def _sweep(tmp_path: Path, *args: str) -> subprocess.Popen:
    (tmp_path / "run.py").write_text(SCRIPT)
    env = {**os.environ, "PYTHONPATH": f"{TESTS}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    return subprocess.Popen(
        [sys.executable, str(tmp_path / "run.py"), "sweep", *args, "--workers", "1"],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a terminal's foreground job
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def test_ctrl_c_reaches_the_client_only(tmp_path):
    """A terminal's Ctrl-C goes to the whole process group: workers that heard it died
    mid-import with KeyboardInterrupt tracebacks (and CancelledErrors) while the client
    was already stopping. They start with it ignored; the client's handler is back after."""
    import signal as _signal

    from formgraph.sweeps import cluster

    before = _signal.getsignal(_signal.SIGINT)
    with cluster.connect(None, workers=1) as client:
        assert _signal.getsignal(_signal.SIGINT) is before
        seen = client.run(_signal.getsignal, _signal.SIGINT)
    assert list(seen.values()) == [_signal.SIG_IGN]


def test_a_worker_warning_is_one_line_of_ours(tmp_path):
    (tmp_path / "g.yaml").write_text(
        "formgraph: 1\n# a comment, so the file's lines are not the re-written YAML's\n\n"
        "params:\n  s: 1.0\nnodes:\n"
        "  m: {type: mesh.from_faces, vertices: [[0, 0, 0], ['=s', 0, 0], [0, 1, 0]], "
        "faces: [[0, 1, 2]]}\n\n  # measured\n  q: {type: mesh.measure, mesh: '@m'}\n"
    )
    p = _sweep(tmp_path, "g.yaml", "--vary", "s=1,2", "--measure", "q.area", "--no-cache")
    out, err = p.communicate(timeout=180)
    assert p.returncode == 0, err
    lines = [x for x in err.splitlines() if x.strip()]
    assert lines and all(x.startswith("formgraph: warning: ") for x in lines), err
    assert "g.yaml:10: node 'q'" in err, err  # the file's own line, not the re-written text's
    assert "not watertight" in err and "_task_spec" not in err and "FormgraphWarning" not in err
