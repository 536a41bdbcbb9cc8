"""Studio: slider to picture in headless chromium, and the page's first picture.

``formgraph serve`` runs on a copy of the spiral tube (16k faces) in a subprocess; Playwright
drives Debian's chromium (SwiftShader WebGL, so drawing is on the CPU like the rest). A
script put in the page before it loads records, with the page's own clock, every websocket
message (arrival and bytes), every WebGL draw call and every key press. One slider step is
then split into:

- recook: the engine's evaluation (the server's own measure, in the page's ``#timing``);
- server: the rest of the server's time, from the request reaching the worker to the
  scene's changes sent (the queue, the datasets drawn, the arrays copied in place, the
  page's state), also its own measure;
- transfer: the rest of the time until the step's last websocket message before the
  picture (the trigger sent; the step's new arrays, its scene and the page's state
  received and decoded: the arrays go ahead of the scene, vtk.js asks for none);
- drawing: from that message to the last draw call (vtk.js building its buffers and
  issuing the draw; SwiftShader's rasterizing runs in chromium's GPU process after it).

The step is the ``thickness`` slider (the section circle and all below it recompute, the
spiral is cached), moved by one key press; median of the steps. Measured on a busy machine:
compare rows of one run only.
"""

from __future__ import annotations

import json
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STEPS = 9
WAIT_MS = 90_000  # for the page's first load (as the studio tests wait)

PROBE = """
window.__fg = {ws: [], draws: [], keys: []};
(() => {
  const W = window.WebSocket;
  function Probe(...args) {
    const ws = new W(...args);
    ws.addEventListener('message', (e) => {
      const d = e.data;
      const n = d.size !== undefined ? d.size
        : (d.byteLength !== undefined ? d.byteLength : d.length);
      window.__fg.ws.push([performance.now(), n || 0]);
    });
    return ws;
  }
  Probe.prototype = W.prototype;
  for (const k of ['CONNECTING', 'OPEN', 'CLOSING', 'CLOSED']) Probe[k] = W[k];
  window.WebSocket = Probe;
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
    const ctx = getContext.call(this, type, ...rest);
    if (ctx && /webgl/.test(type) && !ctx.__fg) {
      ctx.__fg = true;
      for (const f of ['drawElements', 'drawArrays']) {
        const draw = ctx[f].bind(ctx);
        ctx[f] = (...a) => { window.__fg.draws.push(performance.now()); return draw(...a); };
      }
    }
    return ctx;
  };
  document.addEventListener('keydown', () => window.__fg.keys.push(performance.now()), true);
})();
"""


def _start(graph: Path, out: Path) -> tuple[subprocess.Popen, str]:
    log = open(graph.parent / "studio.log", "w")  # noqa: SIM115  (closed with the folder)
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "formgraph.cli.main",
            "serve",
            str(graph),
            "--port",
            "0",
            "--no-browser",
        ]
        + ["--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=log,
        text=True,
    )
    line: list[str] = []
    reader = threading.Thread(target=lambda: line.append(proc.stdout.readline()))
    reader.start()
    reader.join(WAIT_MS / 1000)
    if not line or not line[0].startswith("http"):
        proc.kill()
        log.close()
        text = (graph.parent / "studio.log").read_text()[-2000:]
        raise RuntimeError(f"the studio did not start: {line} {text}")
    return proc, line[0].strip()


def _quiet(page, since: float, seconds: float = 0.4, timeout: float = 60.0) -> None:
    """Wait until no message or draw call came for ``seconds`` (page clock)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        last = page.evaluate(
            "Math.max(0, ...window.__fg.ws.map(m => m[0]), ...window.__fg.draws.slice(-1))"
        )
        now = page.evaluate("performance.now()")
        if last > since and now - last > seconds * 1000:
            return
        time.sleep(0.1)
    raise RuntimeError("the page did not settle")


def run(table) -> None:
    chromium = shutil.which("chromium")
    case_step = "studio: slider to picture, spiral tube 16k faces"
    case_load = "studio: page interactive (first picture)"
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        table.add(case_step, "formgraph", None, "not installed (playwright)")
        return
    if chromium is None:
        table.add(case_step, "formgraph", None, "not installed (chromium)")
        return
    folder = Path(tempfile.mkdtemp(prefix="fg-bench-studio-"))
    graph = folder / "spiral_tube.yaml"
    shutil.copy(ROOT / "graphs" / "spiral_tube.yaml", graph)
    proc, url = _start(graph, folder / "out")
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(
                executable_path=chromium,
                args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
            )
            page = browser.new_page(viewport={"width": 1400, "height": 850})
            page.add_init_script(PROBE)
            page.goto(url)
            page.wait_for_function("window.__fg && window.__fg.draws.length > 0", timeout=WAIT_MS)
            page.wait_for_function(  # (a first run after a quiet spell imports slowly)
                "document.querySelector('#status')?.innerText.includes('computed')",
                timeout=WAIT_MS,
            )
            _quiet(page, 0.0)
            # the page is usable once the model is drawn: the last draw of the first load,
            # on the page's clock (which starts at the navigation)
            drawn = page.evaluate("window.__fg.draws[window.__fg.draws.length - 1]")
            table.add(case_load, "formgraph", [drawn / 1000], "navigation to the model drawn")
            page.wait_for_selector("#editor .view-lines", timeout=WAIT_MS)
            editor = page.evaluate("performance.now()")  # (to within Playwright's polling)
            table.add(
                "  the editor (Monaco, loaded after the picture)",
                "formgraph",
                [editor / 1000],
                "navigation to the editor shown",
            )
            _quiet(page, 0.0)

            thumb = page.locator(".fg-slider-thickness .v-slider-thumb")
            thumb.focus()
            rows = []
            for _ in range(STEPS):
                n_ws = page.evaluate("window.__fg.ws.length")
                n_draw = page.evaluate("window.__fg.draws.length")
                # (the timing, not the status: two steps may have the same status text,
                # "5 computed, 1 cached in 41 ms", and waiting for it to change timed out)
                before = page.inner_text("#timing")
                page.keyboard.press("ArrowRight")  # each step a new value: no cache hit
                page.wait_for_function(
                    f"document.querySelector('#timing').innerText != {json.dumps(before)}",
                    timeout=WAIT_MS,
                )
                key = page.evaluate("window.__fg.keys[window.__fg.keys.length - 1]")
                _quiet(page, key)
                fg = page.evaluate(
                    f"({{ws: window.__fg.ws.slice({n_ws}), "
                    f"draws: window.__fg.draws.slice({n_draw})}})"
                )
                timing = json.loads(page.inner_text("#timing") or "{}")
                m = re.search(r"(\d+) computed, (\d+) cached", page.inner_text("#status"))
                draws = [d for d in fg["draws"] if d >= key]
                drawn = max(draws, default=key)
                # what came before the picture was drawn (the page sends the graph's drawing
                # and the whole scene for later pages once the steps settle, after it)
                ws = [w for w in fg["ws"] if key <= w[0] <= drawn]
                if not ws or not draws:
                    continue
                last = ws[-1][0]
                server = (
                    timing.get("asked_to_done_ms", 0.0)
                    + timing.get("state_ms", 0.0)
                    + timing.get("scene_ms", 0.0)
                ) / 1000
                total = (drawn - key) / 1000
                draw = (drawn - last) / 1000
                recook = timing.get("cook_ms", 0.0) / 1000
                rows.append(
                    {
                        "total": total,
                        "recook": recook,
                        "server": max(0.0, server - recook),
                        "transfer": max(0.0, total - server - draw),
                        "draw": draw,
                        "bytes": sum(w[1] for w in ws),
                        "nodes": m.group(0) if m else "?",
                    }
                )
            browser.close()
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
        shutil.rmtree(folder, ignore_errors=True)
    if not rows:
        table.add(case_step, "formgraph", None, "no step was measured")
        return

    def values(key: str) -> list[float]:
        return [r[key] for r in rows]

    kib = statistics.median(r["bytes"] for r in rows) / 1024
    table.add(
        case_step,
        "formgraph",
        values("total"),
        f"median [range] of {len(rows)} key presses, the page's clock; {rows[0]['nodes']}; "
        f"{kib:.0f} KiB sent before each picture",
    )
    parts = [
        ("recook", "the engine's evaluation"),
        ("server", "the rest of the server: queue, datasets, arrays in place, scene sent"),
        ("transfer", "the rest until the last message: trigger in, arrays and scene out"),
        ("draw", "last message to last draw call (vtk.js)"),
    ]
    for key, note in parts:
        table.add(f"  of which {key}", "formgraph", values(key), note)
