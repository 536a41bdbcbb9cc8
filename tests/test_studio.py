"""The studio (formgraph.studio): its guard, its session and worker, and the page in a real
browser (Debian's chromium driven by Playwright; those tests are skipped without them).

One studio serves every browser test: started as ``formgraph serve`` in a subprocess on
127.0.0.1 and a free port, on a copy of the spiral tube, and always stopped.
"""

from __future__ import annotations

import io
import re
import shutil
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from formgraph.core.errors import Problem, Where
from formgraph.studio.guard import Guard, _split_host, cookie_name
from formgraph.studio.session import StudioSession, Superseded, controls_of
from formgraph.studio.worker import Worker

GRAPHS = Path(__file__).resolve().parent.parent / "graphs"
TUBE = GRAPHS / "spiral_tube.yaml"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

# --------------------------------------------------------------------------------- guard

LOCAL = ("127.0.0.1", 8765)


# how long a page waits for a state before the test fails: SwiftShader's WebGL, chromium and
# the first cook share two cores with the other test worker, and a load spike made 30 s flaky
WAIT_MS = 90_000


def _guard() -> Guard:
    return Guard("s3cret-token")


def test_guard_lets_the_page_through():
    g = _guard()
    assert g.problem("127.0.0.1:8765", LOCAL, None, False, "s3cret-token") is None
    assert g.problem("localhost:8765", LOCAL, None, False, "s3cret-token") is None
    ws = g.problem("127.0.0.1:8765", LOCAL, "http://127.0.0.1:8765", True, "s3cret-token")
    assert ws is None


@pytest.mark.parametrize(
    "host, origin, websocket, token, why",
    [
        ("127.0.0.1:8765", None, False, None, "token"),
        ("127.0.0.1:8765", None, False, "s3cret-tokem", "token"),
        ("127.0.0.1:8765", None, False, "", "token"),
        # DNS rebinding: a name that resolves to 127.0.0.1 but is not this server's
        ("evil.example:8765", None, False, "s3cret-token", "Host"),
        ("127.0.0.1:9999", None, False, "s3cret-token", "Host"),
        ("", None, False, "s3cret-token", "Host"),
        ("[::1", None, False, "s3cret-token", "Host"),
        # another site's page opening a websocket, or one with no Origin at all
        ("127.0.0.1:8765", "http://evil.example", True, "s3cret-token", "Origin"),
        ("127.0.0.1:8765", None, True, "s3cret-token", "Origin"),
        ("127.0.0.1:8765", "http://localhost:8765", True, "s3cret-token", "Origin"),
        ("127.0.0.1:8765", "http://evil.example", False, "s3cret-token", "Origin"),
    ],
)
def test_guard_refuses(host, origin, websocket, token, why):
    assert why in _guard().problem(host, LOCAL, origin, websocket, token)


def test_guard_other_addresses():
    g = Guard("t", names=["studio.lan"])
    assert g.problem("studio.lan:80", ("10.0.0.5", 80), None, False, "t") is None
    assert g.problem("10.0.0.5:80", ("10.0.0.5", 80), None, False, "t") is None
    # localhost is this machine only when the server listens on a loopback address
    assert "Host" in g.problem("localhost:80", ("10.0.0.5", 80), None, False, "t")
    assert g.problem("[::1]:80", ("::1", 80), None, False, "t") is None
    assert g.problem("127.0.0.1:80", ("::ffff:127.0.0.1", 80), None, False, "t") is None


@pytest.mark.parametrize(
    "text, parsed",
    [
        ("127.0.0.1:8765", ("127.0.0.1", 8765)),
        ("LOCALHOST", ("localhost", None)),
        ("[::1]:80", ("::1", 80)),
        ("::1", None),
        ("a:b", None),
        ("[::1]x", None),
    ],
)
def test_split_host(text, parsed):
    assert _split_host(text) == parsed


def test_cookie_names_differ_by_port():
    assert cookie_name(8765) != cookie_name(8766)


# ------------------------------------------------------------------------------ session


@pytest.fixture
def tube(tmp_path):
    path = tmp_path / "tube.yaml"
    shutil.copy(TUBE, path)
    return path


def test_session_recooks_what_a_param_reaches(tube, tmp_path):
    s = StudioSession(tube, out_dir=tmp_path / "out", sets=["turns=2"])
    first = s.open()
    assert first.ok and first.new_graph
    assert s.values == {"turns": 2}
    assert first.computed == len(first.stats)  # a cold start computes everything
    [(label, mesh)] = first.shown
    assert label == "solid" and mesh.n_faces > 10_000
    step = s.set_params(turns=3)
    assert step.ok
    # turns reaches the spiral and all below it, not the circle of the section
    assert step.stats["section"].status == "cached"
    assert step.stats["spiral"].status == "computed"
    assert (step.computed, step.cached) == (len(step.stats) - 1, 1)
    assert step.shown[0][1].n_faces == mesh.n_faces
    assert not np.array_equal(step.shown[0][1].vertices, mesh.vertices)


def test_session_keeps_the_last_good_result(tube, tmp_path):
    s = StudioSession(tube, out_dir=tmp_path / "out")
    good = s.open()
    text = tube.read_text()
    broken = s.open(text.replace("nurbs.sweep", "nurbs.sweeep"))
    assert not broken.ok
    assert broken.shown is good.shown  # the picture stays the last good one
    (problem,) = broken.problems
    assert problem.where.line == text.splitlines().index("    type: nurbs.sweep") + 1
    assert "did you mean 'nurbs.sweep'" in problem.message
    assert s.graph is not None and "tube" in s.graph.nodes  # the old version still runs
    fixed = s.open(text)
    assert fixed.ok and fixed.computed == 0  # its cache survived the broken version
    yaml_typo = s.open(text + "\n  oops: [\n")
    assert not yaml_typo.ok and yaml_typo.problems[0].where.line is not None


def test_session_refuses_a_bad_param_value(tube, tmp_path):
    s = StudioSession(tube, out_dir=tmp_path / "out")
    s.open()
    bad = s.set_params(turns=99)
    assert not bad.ok and "turns" in bad.message and "12" in bad.message
    assert "turns" not in s.values  # left as it was
    assert s.reset_params().ok


def test_session_save_and_run_write_only_their_files(tube, tmp_path):
    out = tmp_path / "out"
    s = StudioSession(tube, out_dir=out)
    s.open()
    text = "# saved from the studio\n" + tube.read_text()
    s.save(text)
    assert tube.read_text() == text
    assert sorted(p.name for p in tube.parent.iterdir()) == ["tube.yaml"]  # no temp file
    ran = s.run()
    assert ran.ok and s.exports() == ["tube.stl"]
    assert (out / "tube.stl").stat().st_size > 10_000


def test_session_a_failing_node_names_itself(tmp_path):
    path = tmp_path / "g.yaml"
    path.write_text(
        "formgraph: 1\n"
        "params:\n"
        "  how: {default: value}\n"
        "nodes:\n"
        "  ok:\n"
        "    type: stub.value\n"
        "    x: 2\n"
        "  bad:\n"
        "    type: stub.fail\n"
        "    x: '@ok'\n"
        "    how: =how\n"
    )
    s = StudioSession(path, out_dir=tmp_path / "out")
    cooked = s.open()
    assert not cooked.ok and cooked.failed == ["bad"]
    (problem,) = cooked.problems
    assert problem.where.node == "bad" and problem.where.line == 8  # the node's line
    assert problem.message == "(stub.fail): this node always fails"
    assert cooked.stats["ok"].status == "computed"
    assert s.graph is not None  # a version that checks is current: a param may fix it


def test_session_watches_its_subgraph_files(tmp_path):
    (tmp_path / "part.yaml").write_text(
        "formgraph: 1\n"
        "params:\n"
        "  r: {default: 1.0}\n"
        "outputs:\n"
        "  pts: '@pts'\n"
        "nodes:\n"
        "  pts:\n"
        "    type: points.circle\n"
        "    count: 6\n"
        "    radius: =r\n"
    )
    main = tmp_path / "main.yaml"
    main.write_text("formgraph: 1\nnodes:\n  ring:\n    type: part.yaml\n    r: 2.0\n")
    s = StudioSession(main, out_dir=tmp_path / "out")
    assert s.open().ok
    assert [p.name for p in s.files()] == ["main.yaml", "part.yaml"]
    # a broken part is still watched, so that fixing it reloads
    (tmp_path / "part.yaml").write_text("formgraph: 1\nnodes:\n  pts:\n    type: nope\n")
    assert not s.open().ok
    assert [p.name for p in s.files()] == ["main.yaml", "part.yaml"]


def test_session_watches_and_rereads_its_input_files(tmp_path):
    (tmp_path / "pts.csv").write_text("x,y,z\n0,0,0\n1,0,0\n")
    main = tmp_path / "main.yaml"
    main.write_text("formgraph: 1\nnodes:\n  pts:\n    type: read.points\n    path: pts.csv\n")
    s = StudioSession(main, out_dir=tmp_path / "out")
    first = s.open()
    assert first.ok and len(first.shown[0][1]) == 2
    assert [p.name for p in s.files()] == ["main.yaml", "pts.csv"]
    (tmp_path / "pts.csv").write_text("x,y,z\n0,0,0\n1,0,0\n2,0,0\n")
    again = s.cook()  # the input's bytes are in its key: a recook reads it again
    assert again.ok and len(again.shown[0][1]) == 3 and again.computed == 1


def test_node_warnings_are_located(tmp_path):
    path = tmp_path / "g.yaml"
    path.write_text(
        "formgraph: 1\n"
        "nodes:\n"
        "  box: {type: mesh.box}\n"
        "  smooth:\n"
        "    type: mesh.catmull_clark\n"
        "    mesh: '@box'\n"
        "    sharpness: 2\n"
    )
    cooked = StudioSession(path, out_dir=tmp_path / "out").open()
    assert cooked.ok
    (w,) = cooked.warnings
    assert (w.where.node, w.where.line) == ("smooth", 4)
    assert "sharpness has no effect without crease_angle" in w.message


def test_controls_from_param_types(tmp_path):
    path = tmp_path / "g.yaml"
    path.write_text(
        "formgraph: 1\n"
        "params:\n"
        "  n: {type: int, default: 3, min: 1, max: 9}\n"
        "  r: {default: 0.5, min: 0.0, max: 2.0}\n"
        "  free: 1.5\n"
        "  flag: true\n"
        "nodes:\n"
        "  pts:\n"
        "    type: points.circle\n"
        "    count: =n\n"
        "    radius: =r * free\n"
    )
    s = StudioSession(path, out_dir=tmp_path / "out")
    assert s.open().ok
    kinds = {c.name: (c.kind, c.step) for c in controls_of(s.graph, s.values)}
    assert kinds == {
        "n": ("slider", 1.0),
        "r": ("slider", 0.02),
        "free": ("number", None),
        "flag": ("toggle", None),
    }


# ------------------------------------------------------------------------------- worker


def test_worker_newest_request_supersedes_the_running_one():
    delivered = []
    done = threading.Event()
    started = threading.Event()
    release = threading.Event()

    def deliver(kind, result, seconds):
        delivered.append((kind, result))
        if result == "third":
            done.set()

    w = Worker(deliver, lambda kind, exc: delivered.append(("error", repr(exc))))

    def slow(name):
        started.set()
        release.wait(5)
        w.check()  # between two nodes: a newer request of this kind stops this one
        return name

    try:
        w.submit("params", slow, "first")
        assert started.wait(5)
        w.submit("params", slow, "second")  # waits, then is replaced by the third
        w.submit("params", lambda: "third")
        release.set()
        assert done.wait(5)
    finally:
        w.stop()
    assert delivered == [("params", "third")]
    assert w.superseded == 2


def test_worker_idle_can_leave_background_kinds_aside():
    release = threading.Event()
    w = Worker(lambda *a: None, lambda *a: None)
    try:
        w.submit("drawing", release.wait, 5)
        time.sleep(0.05)  # running now
        assert not w.idle() and w.idle(ignore=("drawing",))
        w.submit("params", lambda: None)  # waiting behind the drawing
        assert not w.idle(ignore=("drawing",))
    finally:
        release.set()
        w.stop()


def test_the_busy_spinner_ends_with_a_step_even_when_a_drawing_is_queued(tube, tmp_path):
    """Step N settles (its drawing of the graph queued) while step N+1 cooks: when N+1 is
    applied, only that drawing waits, and the page is not busy (the spinner stayed on for
    good: nothing after the drawing cleared it; found by review)."""
    from formgraph.studio.page import Page

    class Timers:  # the page's loop, fired by hand
        def __init__(self):
            self.timers = []

        def call_later(self, _delay, fn):
            timer = threading.Timer(3600, fn)  # never started: only fired below
            self.timers.append(timer)
            return timer

        def call_soon_threadsafe(self, fn, *args):
            fn(*args)

        def fire(self):
            live, self.timers = [t for t in self.timers if not t.finished.is_set()], []
            for t in live:
                t.function()

    s = StudioSession(tube, out_dir=tmp_path / "out")
    page = Page(s, Guard("t"))
    try:
        deadline = time.time() + 60
        while not (page.worker.idle() and page._early) and time.time() < deadline:
            time.sleep(0.05)  # the first cook delivered (kept for a loop not yet there)
        page._early.clear()
        page.loop = loop = Timers()
        release = threading.Event()
        page._apply("params", s.set_params(thickness=0.3), 0.0, (None, None, page._snapshot()))

        def step():  # step N+1, cooking until released
            release.wait(5)
            return s.set_params(thickness=0.35)

        applied = page._apply

        def apply(kind, result, *rest):
            applied(kind, result, *rest)
            if kind == "params":
                seen.append(page.state.busy)

        seen: list[bool] = []
        page._apply = apply

        page.worker.submit("params", step)
        time.sleep(0.05)
        loop.fire()  # step N's settle timer fires while N+1 cooks: its drawing queued
        assert page.worker.waiting("drawing")
        release.set()  # N+1 done and applied, the drawing still to run
        deadline = time.time() + 30
        while not seen and time.time() < deadline:
            time.sleep(0.02)
        assert seen == [False]  # step N+1 applied: not busy, its drawing queued or not
    finally:
        page.close()


def test_superseded_is_not_a_formgraph_error():
    from formgraph.core.errors import FormgraphError

    assert not issubclass(Superseded, FormgraphError)


@pytest.mark.parametrize(
    "args, code, message",
    [
        (["missing.yaml"], 1, "no such graph file"),
        (["g.yaml", "--port", "70000"], 2, "a port is 0 to 65535"),
        (["g.yaml", "--set", "turns"], 2, "--set takes NAME=VALUE"),
    ],
)
def test_serve_command_line_errors(tmp_path, capsys, args, code, message):
    from formgraph.cli.main import main

    shutil.copy(TUBE, tmp_path / "g.yaml")
    argv = ["serve", *(str(tmp_path / a) if a.endswith(".yaml") else a for a in args)]
    if "port" in message:  # argparse's own check of the option: exits 2
        with pytest.raises(SystemExit) as exc:
            main([*argv, "--no-browser"])
        assert exc.value.code == code
    else:
        assert main([*argv, "--no-browser"]) == code
    assert message in capsys.readouterr().err


def test_import_formgraph_does_not_import_trame():
    code = "import sys, formgraph, formgraph.studio; print(any('trame' in m for m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "False", out.stderr


# ------------------------------------------------------------------------ live server


class Studio:
    """``formgraph serve`` in a subprocess; ``url`` is the first line it printed."""

    def __init__(self, graph: Path, out: Path):
        self.graph = graph
        self.out = out
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "formgraph.cli.main",
                "serve",
                str(graph),
                "--port",
                "0",
                "--no-browser",
                "--out",
                str(out),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=graph.parent,
        )
        line: list[str] = []
        reader = threading.Thread(target=lambda: line.append(self.proc.stdout.readline()))
        reader.start()
        reader.join(60)
        if not line or not line[0].startswith("http://"):
            self.close()
            raise RuntimeError(f"the studio did not start: {line} {self.proc.stderr.read()}")
        self.url = line[0].strip()
        m = re.match(r"http://([^/]+)/index\.html\?token=([\w-]+)$", self.url)
        assert m, self.url
        self.address, self.token = m.group(1), m.group(2)
        self.base = f"http://{self.address}"

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        for stream in (self.proc.stdout, self.proc.stderr):
            if stream is not None:
                stream.close()


@pytest.fixture(scope="module")
def studio(tmp_path_factory):
    folder = tmp_path_factory.mktemp("studio")
    graph = folder / "spiral_tube.yaml"
    shutil.copy(TUBE, graph)
    s = Studio(graph, folder / "out")
    try:
        yield s
    finally:
        s.close()


def _get(url: str, headers: dict[str, str] | None = None) -> tuple[int, str, dict[str, str]]:
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=20) as r:
            return r.status, r.read().decode("utf-8", "replace"), dict(r.headers)
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read().decode("utf-8", "replace"), dict(exc.headers)


def test_served_on_loopback_with_a_token(studio):
    assert studio.address.startswith("127.0.0.1:")
    assert len(studio.token) >= 40  # secrets.token_urlsafe(32)


def test_requests_without_the_token_are_refused(studio):
    for path in ("/", "/index.html", "/index.html?token=wrong", "/ws", "/nothing-here"):
        status, body, headers = _get(studio.base + path)
        assert status == 403, path
        assert "token" in body and "<html" not in body.lower()
        assert "Set-Cookie" not in headers
    status, body, headers = _get(studio.url)
    assert status == 200 and "<html" in body.lower()
    assert studio.token in headers["Set-Cookie"] and "HttpOnly" in headers["Set-Cookie"]
    assert headers["X-Frame-Options"] == "DENY"
    cookie = f"{cookie_name(int(studio.address.split(':')[1]))}={studio.token}"
    assert _get(studio.base + "/index.html", {"Cookie": cookie})[0] == 200


def test_wrong_host_and_origin_are_refused(studio):
    port = studio.address.split(":")[1]
    assert _get(studio.url, {"Host": f"evil.example:{port}"})[0] == 403
    ws = {
        "Connection": "Upgrade",
        "Upgrade": "websocket",
        "Sec-WebSocket-Version": "13",
        "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==",
    }
    ws_url = f"{studio.base}/ws?token={studio.token}"
    status, body, _ = _get(ws_url, {**ws, "Origin": "http://evil.example"})
    assert status == 403 and "Origin" in body
    assert _get(ws_url, ws)[0] == 403  # no Origin at all (the page's own: the browser tests)


# ---------------------------------------------------------------------------- browser


# the time of the page's first WebGL draw call (page clock), and what the page sends on its
# websocket (and the socket's binaryType then), put in before the page loads
FIRST_DRAW = """
(() => {
  window.__fgWire = {sent: [], binaryType: null};
  const send = WebSocket.prototype.send;
  WebSocket.prototype.send = function (data) {
    const out = send.call(this, data);
    window.__fgWire.sent.push(new TextDecoder('latin1').decode(data));
    window.__fgWire.binaryType = this.binaryType;
    return out;
  };
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
    const ctx = getContext.call(this, type, ...rest);
    if (ctx && /webgl/.test(type) && !ctx.__fg) {
      ctx.__fg = true;
      for (const f of ['drawArrays', 'drawElements']) {
        const draw = ctx[f].bind(ctx);
        ctx[f] = (...a) => {
          if (window.__fgFirstDraw === undefined) window.__fgFirstDraw = performance.now();
          return draw(...a);
        };
      }
    }
    return ctx;
  };
})();
"""


@pytest.fixture(scope="module")
def page(studio):
    if CHROMIUM is None:
        pytest.skip("no chromium here (apt-get install chromium; .ci/run installs it)")
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="playwright is not installed (pip install playwright)"
    )
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM,
            # without SwiftShader, WebGL canvases stay blank in headless chromium
            args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
        )
        try:
            pg = browser.new_page(viewport={"width": 1400, "height": 850})
            pg.set_default_timeout(WAIT_MS)
            pg.add_init_script(FIRST_DRAW)
            pg.goto(studio.url)
            pg.wait_for_function(
                "document.querySelector('#status')?.innerText.includes('computed')"
            )
            pg.wait_for_selector("#editor .view-lines")  # Monaco, loaded after the picture
            yield pg
        finally:
            browser.close()


def _canvas(pg) -> np.ndarray:
    from PIL import Image

    png = pg.locator("#view canvas").first.screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def _shows_model(img: np.ndarray) -> float:
    """The fraction of the canvas that is not the white background."""
    return float(np.mean(np.abs(img - 255).sum(axis=2) > 60))


def _wait_picture(pg, before: np.ndarray, seconds: float = 20.0) -> np.ndarray:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        img = _canvas(pg)
        if img.shape == before.shape and np.mean(np.abs(img - before).sum(axis=2) > 60) > 0.005:
            return img
        time.sleep(0.2)
    raise AssertionError("the picture did not change")


def _status(pg) -> str:
    return pg.inner_text("#status")


def _timing(pg) -> str:
    """The last step's timing, which names the step: two steps can have the same status
    ("5 computed, 1 cached in 41 ms"), so a wait for the status to change can hang."""
    return pg.inner_text("#timing")


def test_page_shows_the_model(page):
    end = time.monotonic() + 20
    while _shows_model(_canvas(page)) < 0.02 and time.monotonic() < end:
        time.sleep(0.2)
    img = _canvas(page)
    assert _shows_model(img) > 0.02
    # the palette's first colour (#1f77b4) is where the mesh is
    blue = (np.abs(img - [31, 119, 180]).sum(axis=2) < 120) & (img[..., 2] > img[..., 0] + 40)
    assert blue.mean() > 0.01
    assert "type: nurbs.sweep" in page.inner_text("#editor").replace("\xa0", " ")
    assert page.locator("#graph [data-node='tube']").count() == 1
    assert re.search(r"\d+ computed, \d+ cached in", _status(page))


def test_the_editor_loads_after_the_first_picture(page):
    """Monaco (most of the page's script) is not what the page starts with: it is fetched
    once the model is drawn, and then edits as before (the tests below type in it)."""
    started = page.evaluate(
        "performance.getEntriesByType('resource')"
        ".find(r => r.name.includes('trame-code.umd.js'))?.startTime"
    )
    drawn = page.evaluate("window.__fgFirstDraw")
    assert drawn is not None and started is not None and started > drawn
    scripts = page.evaluate("window.trame.state.get('trame__scripts')")
    assert scripts and not any("trame-code" in u for u in scripts)
    assert page.locator("#editor .view-lines").count() == 1


def _turns(pg) -> int:
    return int(re.search(r"turns = (\d+)", pg.inner_text("#controls")).group(1))


def test_slider_recooks_and_redraws(page):
    before, turns = _canvas(page), _turns(page)
    thumb = page.locator(".fg-slider-turns .v-slider-thumb")
    thumb.focus()
    page.keyboard.press("ArrowRight" if turns < 12 else "ArrowLeft")
    page.wait_for_function("document.querySelector('#status').innerText.includes('1 cached')")
    after = _wait_picture(page, before)
    assert _shows_model(after) > 0.02
    m = re.search(r"(\d+) computed, (\d+) cached", _status(page))
    assert m and (int(m.group(1)), int(m.group(2))) == (5, 1)  # the section circle stays
    assert _turns(page) == (turns + 1 if turns < 12 else turns - 1)


def _z_extent(stl: Path) -> float:
    import trimesh

    return float(np.ptp(trimesh.load(stl, file_type="stl").vertices[:, 2]))


def test_every_key_press_counts_while_a_step_recooks(page, studio):
    """Four presses, each while the step of the one before still cooks, move the slider four
    steps, and the session cooks the last value (the run's tube is that many turns tall):
    a step's result sent back the value it cooked, over a press still on its way."""
    turns = _turns(page)
    key, sign = ("ArrowRight", 1) if turns <= 8 else ("ArrowLeft", -1)
    page.locator(".fg-slider-turns .v-slider-thumb").focus()
    for _ in range(4):
        page.keyboard.press(key)
        page.wait_for_timeout(60)  # a step of the tube cooks for some 80-300 ms
    page.wait_for_function("window.trame.state.get('busy') === false")
    page.wait_for_timeout(1000)  # any step still on its way lands
    assert _turns(page) == turns + 4 * sign
    stl = studio.out / "tube.stl"
    before = stl.stat().st_mtime_ns if stl.exists() else None
    page.click("#run")
    end = time.monotonic() + 60
    while (not stl.exists() or stl.stat().st_mtime_ns == before) and time.monotonic() < end:
        time.sleep(0.1)
    time.sleep(0.2)  # written atomically: whole once it is there
    thickness = float(re.search(r"thickness = ([\d.]+)", page.inner_text("#controls"))[1])
    # z = t / 2 pi over `turns` turns, and the tube's radius above and below
    assert _z_extent(stl) == pytest.approx(turns + 4 * sign + 2 * thickness, abs=0.02)
    page.locator(".fg-control", has_text="turns").get_by_text("reset").click()  # back to 3
    page.wait_for_function("document.querySelector('#controls').innerText.includes('turns = 3')")


def test_values_are_shown_to_the_step(page):
    """A value is labelled to its slider step's decimals: radius (step 0.1) as 9.4, not the
    9.399999999999999 a float sum of steps can give; thickness (step 0.01) as 0.30."""
    page.evaluate(
        "window.trame.state.set('params', "
        "{...window.trame.state.get('params'), radius: 9.399999999999999})"
    )
    page.wait_for_function("document.querySelector('#controls').innerText.includes('radius = 9.')")
    text = page.inner_text("#controls")
    assert "radius = 9.4\n" in text + "\n" and "9.39999" not in text
    assert re.search(r"thickness = \d\.\d\d\b", text)
    assert re.search(r"turns = \d+\b(?!\.)", text)
    page.locator(".fg-control", has_text="radius").get_by_text("reset").click()
    page.wait_for_function("document.querySelector('#controls').innerText.includes('radius = 2.0')")


def _open_until_drawn(page, url: str) -> None:
    """Load the studio in ``page`` and wait until its first run is shown and drawn."""
    page.set_default_timeout(WAIT_MS)
    page.goto(url)
    page.wait_for_function("document.querySelector('#status')?.innerText.includes('cached')")
    end = time.monotonic() + 20
    while _shows_model(_canvas(page)) < 0.02 and time.monotonic() < end:
        time.sleep(0.2)


def test_the_page_loads_without_a_console_error_or_a_failed_request(page, studio):
    """Nothing on the console but information, no request refused or failed: the client's
    first POST to paraview/ (a launcher it asks for the websocket's address) was answered
    405 on every load."""
    context = page.context.browser.new_context(viewport=page.viewport_size)
    problems: list[str] = []
    try:
        other = context.new_page()
        other.on(
            "console",
            lambda m: (
                problems.append(f"console {m.type}: {m.text}")
                if m.type in ("error", "warning")
                else None
            ),
        )
        other.on("pageerror", lambda e: problems.append(f"page error: {e}"))
        other.on("requestfailed", lambda r: problems.append(f"failed: {r.url} {r.failure}"))
        other.on(
            "response",
            lambda r: (
                problems.append(f"{r.status} {r.request.method} {r.url}")
                if r.status >= 400
                else None
            ),
        )
        _open_until_drawn(other, studio.url)
        other.wait_for_timeout(2000)  # what loads after the picture (the editor) too
    finally:
        context.close()
    assert problems == []


def test_a_step_sends_its_arrays_ahead_of_its_scene(page):
    """vtk.js gets a step's new arrays with its scene and asks for none; the websocket
    delivers ArrayBuffers, not Blobs (which the browser reads back asynchronously); the
    graph's drawing, with the step's times, follows once the steps settle."""
    before, drawing = _canvas(page), page.inner_html("#graph")
    timing = _timing(page)
    n = page.evaluate("window.__fgWire.sent.length")
    page.locator(".fg-slider-thickness .v-slider-thumb").focus()
    page.keyboard.press("ArrowRight")
    page.wait_for_function(f"document.querySelector('#timing').innerText != {timing!r}")
    _wait_picture(page, before)
    sent = page.evaluate(f"window.__fgWire.sent.slice({n})")
    assert any("set_param" in m and "thickness" in m for m in sent)
    assert not any("viewport.geometry.array.get" in m for m in sent)
    assert page.evaluate("window.__fgWire.binaryType") == "arraybuffer"
    page.wait_for_function(f"document.querySelector('#graph').innerHTML != {drawing!r}")
    assert page.locator("#graph [data-node='tube']").count() == 1  # still clickable


def _aspect(img: np.ndarray) -> float:
    """Height over width of the model's (blue) pixels."""
    rows, cols = np.nonzero(img[..., 2] > img[..., 0] + 40)
    return float(np.ptp(rows) + 1) / float(np.ptp(cols) + 1)


def test_a_page_loaded_after_steps_shows_them(page, studio):
    """A step sends the open page its changes alone; the whole scene, which a page that
    loads later starts from, follows once the steps settle."""
    turns, before = _turns(page), _timing(page)
    page.locator(".fg-slider-turns .v-slider-thumb").focus()
    page.keyboard.press("ArrowRight" if turns < 12 else "ArrowLeft")  # away from the start
    page.wait_for_function(f"document.querySelector('#timing').innerText != {before!r}")
    assert _turns(page) not in (turns, 3)
    time.sleep(1.0)  # past the settle delay
    context = page.context.browser.new_context(viewport=page.viewport_size)
    try:
        other = context.new_page()  # a second tab, or the page reloaded
        _open_until_drawn(other, studio.url)
        # the same tube (the cameras may differ: the first page was framed again as the
        # tube grew), told by its proportions: each turn makes it taller, not wider
        assert _aspect(_canvas(other)) == pytest.approx(_aspect(_canvas(page)), rel=0.12)
    finally:
        context.close()


def test_typo_shows_its_line_and_fixing_recovers(page, studio):
    before = _canvas(page)
    lines = studio.graph.read_text().splitlines()
    line = lines.index("    type: nurbs.sweep") + 1
    page.click("#editor .view-lines")
    page.keyboard.press("Control+Home")
    for _ in range(line - 1):
        page.keyboard.press("ArrowDown")
    page.keyboard.press("End")
    page.keyboard.type("x")
    page.wait_for_function("document.querySelector('#status').classList.contains('bad')")
    problems = page.inner_text("#problems")
    assert f"line {line}:" in problems and "nurbs.sweepx" in problems
    assert "did you mean 'nurbs.sweep'" in problems
    assert page.locator("#editor .squiggly-error").count() >= 1  # marked in the editor
    assert "last version that worked" in _status(page)
    assert np.mean(np.abs(_canvas(page) - before).sum(axis=2) > 60) < 0.005  # kept
    page.keyboard.press("Backspace")
    page.wait_for_function("!document.querySelector('#status').classList.contains('bad')")
    assert re.search(r"\d+ computed, \d+ cached", _status(page))
    assert not page.locator("#problems").is_visible()


def test_save_writes_the_file(page, studio):
    page.click("#editor .view-lines")
    page.keyboard.press("Control+Home")
    page.keyboard.type("# tuned in the studio\n")
    page.click("#save")
    page.wait_for_function("document.querySelector('#status').innerText.includes('saved')")
    text = studio.graph.read_text()
    assert text.startswith("# tuned in the studio\nformgraph: 1\n")
    assert text.endswith("path: tube.stl\n")
    assert sorted(p.name for p in studio.graph.parent.iterdir() if p.is_file()) == [
        "spiral_tube.yaml"
    ]


def test_save_right_after_an_edit_saves_the_edit(page, studio):
    """Typed and saved in one go (the same task of the page, before the text's state update
    can reach the server): the page sends its text with the click, so the edit is saved."""
    before = studio.graph.read_text()
    page.click("#editor .view-lines")
    page.keyboard.press("Control+Home")
    page.evaluate(
        "document.execCommand('insertText', false, '# saved at once\\n');"
        "document.querySelector('#save').click()"
    )
    # (the status may still say 'saved' from an earlier test: wait for the file itself)
    deadline = time.time() + 60
    while studio.graph.read_text() == before and time.time() < deadline:
        time.sleep(0.05)
    assert studio.graph.read_text().startswith("# saved at once\n")


def test_click_a_node_shows_it(page):
    before = _canvas(page)
    page.locator("#graph [data-node='spiral']").click()
    page.wait_for_function("document.querySelector('#graph').innerText.includes('showing spiral')")
    curve = _wait_picture(page, before)
    assert _shows_model(curve) < _shows_model(before) / 2  # a thin curve, not the tube
    page.get_by_text("show results").click()
    page.wait_for_function("document.querySelector('#graph').innerText.includes('results')")
    _wait_picture(page, curve)


def test_an_edit_on_disk_reloads(page, studio):
    # turns set by its control (whatever ran before on this page): a reload keeps it
    before, turns = _timing(page), _turns(page)
    page.locator(".fg-slider-turns .v-slider-thumb").focus()
    page.keyboard.press("ArrowRight" if turns < 12 else "ArrowLeft")
    page.wait_for_function(f"document.querySelector('#timing').innerText != {before!r}")
    page.wait_for_function(
        f"!document.querySelector('#controls').innerText.includes('turns = {turns}\\n')"
    )
    text, turns = studio.graph.read_text(), _turns(page)
    studio.graph.write_text(text.replace("default: 3, min: 1", "default: 2, min: 1"))
    page.wait_for_function(
        "document.querySelector('#editor').innerText.includes('default:\u00a02,')"
    )
    page.wait_for_function("document.querySelector('#status').innerText.includes('computed')")
    assert _turns(page) == turns  # the control's value is kept
    # with unsaved edits in the editor, a change on disk does not overwrite them
    page.click("#editor .view-lines")
    page.keyboard.press("Control+End")
    page.keyboard.type("# not saved")
    time.sleep(0.6)  # past the edit delay
    studio.graph.write_text(text)
    page.wait_for_function("document.querySelector('#status').innerText.includes('on disk')")
    assert "# not saved" in page.inner_text("#editor").replace("\xa0", " ")
    page.click("#reload")  # takes the file's text
    page.wait_for_function("!document.querySelector('#editor').innerText.includes('not saved')")
    page.wait_for_function(
        "document.querySelector('#editor').innerText.includes('default:\u00a03,')"
    )


def test_run_writes_the_exports(page, studio):
    page.click("#run")
    page.wait_for_function("document.querySelector('#status').innerText.includes('wrote')")
    assert "tube.stl" in _status(page)
    stl = studio.out / "tube.stl"
    assert stl.read_bytes()[:5] != b"solid" and stl.stat().st_size > 100_000  # binary STL


def test_page_without_the_token_is_refused(page, studio):
    context = page.context.browser.new_context()  # no cookie from the page's first visit
    try:
        other = context.new_page()
        response = other.goto(studio.base + "/index.html")
        assert response.status == 403
        assert "token" in other.inner_text("body")
        assert page.context.cookies()[0]["httpOnly"]  # the page's own visit kept its cookie
    finally:
        context.close()


HANG = """\
formgraph: 1
params:
  steps: {type: int, default: 12, min: 0, max: 40}
  weight: {default: 0.05, choices: [0.02, 0.05, 0.3], doc: load on each vertex}
nodes:
  net: {type: mesh.plane, size: [10, 10], divisions: [12, 12]}
  hang:
    type: mesh.relax
    simulate: {state: mesh, from: "@net", steps: "=steps"}
    reference: "@net"
    anchors: [0, 12, 156, 168]
    load: [0, 0, "=-weight"]
    stiffness: 3.0
  print: {type: export.stl, mesh: "@hang", path: hang.stl}
"""


def test_frames_and_choices_on_the_page(page, studio):
    """A shown simulated node gets a frame scrubber (steps from the cache, nothing
    recooked); a param with choices a list to pick from."""
    tube = studio.graph.read_text()
    before = _canvas(page)
    studio.graph.write_text(HANG)
    page.wait_for_function("document.querySelector('#editor').innerText.includes('mesh.relax')")
    page.wait_for_function("document.querySelector('#status').innerText.includes('computed')")
    page.wait_for_function("document.querySelector('#frames').innerText.includes('of 12')")
    last = _wait_picture(page, before)
    assert "frame 12 of 12" in page.inner_text("#frames")
    page.locator(".fg-frame-slider .v-slider-thumb").focus()
    page.keyboard.press("Home")
    page.wait_for_function("document.querySelector('#status').innerText.includes('frame 1 of')")
    assert "nothing recooked" in _status(page) and "frame 1 of 12" in page.inner_text("#frames")
    first = _wait_picture(page, last)  # step 1 has barely sagged
    page.keyboard.press("End")
    page.wait_for_function("document.querySelector('#status').innerText.includes('frame 12 of')")
    _wait_picture(page, first)
    page.locator(".fg-choice-weight").click()
    page.locator(".v-overlay .v-list-item", has_text="0.3").click()
    page.wait_for_function("document.querySelector('#status').innerText.includes('cached')")
    m = re.search(r"(\d+) computed, (\d+) cached", _status(page))
    assert m and (int(m.group(1)), int(m.group(2))) == (1, 1)  # the steps; the net cached
    assert "weight = 0.3" in page.inner_text("#controls")
    studio.graph.write_text(tube)
    page.wait_for_function("document.querySelector('#editor').innerText.includes('nurbs.sweep')")
    page.wait_for_function("document.querySelector('#frames').offsetParent === null")


def test_problem_lines_locate():
    from formgraph.studio.page import _markers, _problem_lines

    problems = [Problem(Where("g.yaml", 4, "n", "x"), "bad"), Problem(Where(), "whole graph")]
    assert _markers(problems) == [{"line": 4, "message": "bad", "severity": "error"}]
    assert _problem_lines(problems) == ["line 4: node 'n': bad", "whole graph"]


# ----------------------------------------------------------------------------- scene


def _serialized_actor(actor):
    from trame_vtk.modules.vtk.serializers import (
        SynchronizationContext,
        initialize_serializers,
        serialize,
    )
    from trame_vtk.modules.vtk.serializers.utils import reference_id

    from formgraph.studio.scene import send_back_faces

    initialize_serializers()  # as trame-vtk's protocol does when it starts
    send_back_faces()
    return serialize(None, actor, reference_id(actor), SynchronizationContext(), 0)


def test_back_faces_reach_the_browser(tube, tmp_path):
    from formgraph.studio.scene import StudioScene, make_plotter
    from formgraph.viewer.style import BACK_FACE

    s = StudioSession(tube, out_dir=tmp_path / "out")
    plotter = make_plotter()
    try:
        scene = StudioScene(plotter)
        assert scene.update(s.open().shown)  # actors added
        mesh = scene.parts[("solid", "meshes")].actors[0]
        out = _serialized_actor(mesh)
        calls = {name: args for name, args in out["calls"]}
        assert "setBackfaceProperty" in calls
        back_id = re.fullmatch(r"instance:\$\{(.+)\}", calls["setBackfaceProperty"][0])[1]
        back = next(d for d in out["dependencies"] if d["id"] == back_id)
        red = pv.Color(BACK_FACE).float_rgb
        assert np.allclose(back["properties"]["diffuseColor"], red)
        lines = scene.parts[("solid", "features")].actors[0]
        assert "setBackfaceProperty" not in dict(_serialized_actor(lines)["calls"])
    finally:
        plotter.close()


def test_a_step_changes_arrays_in_place(tube, tmp_path):
    from formgraph.studio.scene import StudioScene, make_plotter

    s = StudioSession(tube, out_dir=tmp_path / "out")
    plotter = make_plotter()
    try:
        scene = StudioScene(plotter)
        scene.update(s.open().shown)
        part = scene.parts[("solid", "meshes")]
        data, actors, added = part.data, list(part.actors), scene.added
        faces = data.GetPolys().GetMTime()
        points = data.GetPoints().GetData()
        assert points.GetDataType() == 10  # VTK_FLOAT: half the bytes of float64
        assert not scene.update(s.set_params(thickness=0.4).shown)  # nothing added
        assert scene.parts[("solid", "meshes")].data is data and part.actors == actors
        assert scene.added == added
        # the faces did not change and were not touched: the same hash, not sent again
        assert data.GetPolys().GetMTime() == faces
        assert data.GetPoints().GetData() is not points  # the points did
        assert data.bounds[5] == pytest.approx(3.4, abs=0.02)  # 3 turns up, 0.4 tube radius
    finally:
        plotter.close()


def test_normals_go_as_int8_within_half_a_degree():
    from formgraph.studio.scene import quantized_normals

    rng = np.random.default_rng(7)
    n = rng.normal(size=(20_000, 3)) * rng.uniform(0.1, 10, size=(20_000, 1))
    n[0] = [0, 0, 0]  # a degenerate normal stays 0, not NaN
    q = quantized_normals(n)
    assert q.dtype == np.int8 and np.abs(q.astype(int)).max() <= 127
    unit = n[1:] / np.linalg.norm(n[1:], axis=1, keepdims=True)
    back = q[1:] / np.linalg.norm(q[1:].astype(float), axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", unit, back), -1, 1)))
    assert angle.max() < 0.5 and (q[0] == 0).all()
    # the same directions give the same bytes: a step that only scales them sends nothing
    assert np.array_equal(quantized_normals(unit * 3.0), quantized_normals(unit))


def test_a_slider_value_is_put_on_its_step():
    from formgraph.studio.page import _as_param
    from formgraph.studio.session import Control

    radius = Control("radius", "slider", 2.0, 2.0, 0.5, 10.0, 0.1)
    assert radius.digits == 1 and radius.as_dict()["digits"] == 1
    assert _as_param(radius, 9.399999999999999) == 9.4
    assert _as_param(radius, 0.5 + 89 * 0.1) == 9.4
    assert _as_param(radius, 10.04) == 10.0 and _as_param(radius, 11) == 10.0
    fine = Control("t", "slider", 0.3, 0.3, 0.05, 1.0, 0.01)
    assert (fine.digits, _as_param(fine, 0.30000000000000004)) == (2, 0.3)
    whole = Control("n", "slider", 3, 3, 1, 12, 1.0)
    assert (whole.digits, _as_param(whole, 7.0), type(_as_param(whole, 7.0))) == (0, 7, int)
    assert Control("x", "slider", 0, 0, 0, 1000, 5.0).digits == 0
    assert Control("x", "number", 0.5, 0.5).digits is None
    assert _as_param(Control("x", "number", 0.5, 0.5), 0.123456) == 0.123456


def test_choice_control_for_an_enum_param():
    import enum
    from types import SimpleNamespace

    from formgraph.core.types import Kind, PortType
    from formgraph.language.model import ParamDef

    class Ends(str, enum.Enum):
        FLAT = "flat"
        ROUND = "round"

    p = ParamDef("ends", Ends.FLAT, PortType((Kind(Ends),)), "Ends")
    graph = SimpleNamespace(params={"ends": Ends.FLAT}, param_defs={"ends": p})
    (c,) = controls_of(graph, {})
    assert (c.kind, c.value, c.choices) == ("choice", "flat", ("flat", "round"))
    assert c.as_dict()["default"] == "flat" and type(c.as_dict()["default"]) is str


def test_choice_control_from_yaml_and_frames_from_the_cache(tmp_path):
    path = tmp_path / "hang.yaml"
    path.write_text(HANG)
    session = StudioSession(path, out_dir=tmp_path / "out")
    cooked = session.open()
    assert cooked.ok and cooked.frames == 12
    c = {c.name: c for c in controls_of(session.graph, session.values)}["weight"]
    assert (c.kind, c.value, c.choices) == ("choice", 0.05, (0.02, 0.05, 0.3))
    steps = session.graph.frames("hang")  # the reference: every step, as the API gives it
    for k in (1, 5, 12):
        f = session.frame(k)
        assert f.frame == k and f.frames == 12
        ((label, mesh),) = f.shown
        assert label == "hang" and np.array_equal(mesh.vertices, steps[k - 1].vertices)
    assert session.frame(99).frame == 12 and session.frame(-3).frame == 1
    assert session.frame(1).shown[0][1].vertices[:, 2].min() > steps[-1].vertices[:, 2].min()
    # a cook of a node that is not simulated: no frames
    assert session.show(["net"]).frames == 0
    assert session.frame(3).frame is None


def test_colour_by_an_attribute(tmp_path):
    from formgraph.studio.scene import StudioScene, make_plotter

    path = tmp_path / "g.yaml"
    path.write_text(
        "formgraph: 1\n"
        "params:\n"
        "  k: {default: 1.0, min: 0.5, max: 4.0}\n"
        "nodes:\n"
        "  box: {type: mesh.box, size: [1, 1, 2]}\n"
        "  tall: {type: attr.set, geometry: '@box', name: tall, value: '=k * z'}\n"
    )
    s = StudioSession(path, out_dir=tmp_path / "out")
    shown = s.open().shown
    plotter = make_plotter()
    try:
        scene = StudioScene(plotter)
        plain = scene.prepare(shown)
        assert plain.attributes == ["tall"] and plain.color_by is None
        assert "tall" not in plain.parts[("tall", "meshes")].point_data  # not sent undrawn
        scene.apply(plain)
        assert scene.apply(scene.prepare(shown, "tall"))  # coloured: actors made again
        mapper = scene.parts[("tall", "meshes")].actors[0].GetMapper()
        assert mapper.GetScalarVisibility() and mapper.GetArrayName() == "tall"
        assert mapper.GetScalarRange() == pytest.approx((-1.0, 1.0))
        assert not scene.apply(scene.prepare(s.set_params(k=3.0).shown, "tall"))
        assert mapper.GetScalarRange() == pytest.approx((-3.0, 3.0))  # follows the values
        assert scene.prepare(shown, "nope").color_by is None  # no such attribute: by node
    finally:
        plotter.close()
