"""The studio page's widgets: the editor, the 3-D view, the graph's drawing, the controls.

Built once with trame's vuetify3 widgets; everything that changes is state (``text``,
``markers``, ``problems``, ``graph_svg``, ``controls``, ``params``, ``status``), set by
:class:`~.page.Page`. The graph's drawing is our SVG with an invisible rectangle over each
node, named by ``data-node``, which a click sends to the server.
"""

from __future__ import annotations

from typing import Any

__all__ = ["ARRAYS", "CSS", "EDITOR_LOADER", "build", "clickable_svg"]

CSS = """
html, body { overflow: hidden; }
.fg-main { display: flex; height: calc(100vh - 48px); }
.fg-left { flex: 0 0 32%; min-width: 0; display: flex; flex-direction: column;
  border-right: 1px solid #ddd; }
.fg-editor { flex: 1 1 auto; min-height: 0; }
.fg-plain { margin: 0; padding: 4px 8px 4px 30px; font: 13px monospace; white-space: pre;
  overflow: auto; height: 100%; color: #333; }
.fg-problems { max-height: 30%; overflow: auto; font: 12px monospace; color: #b00020;
  padding: 4px 8px; border-top: 1px solid #ddd; white-space: pre-wrap; }
.fg-center { flex: 1 1 auto; display: flex; flex-direction: column; min-width: 0; }
.fg-view { flex: 1 1 62%; position: relative; min-height: 0; }
.fg-graph { flex: 0 0 38%; overflow: auto; border-top: 1px solid #ddd; background: white; }
.fg-graph svg { cursor: pointer; max-width: 100%; height: auto; }
.fg-right { flex: 0 0 250px; overflow-y: auto; border-left: 1px solid #ddd; padding: 6px 10px; }
.fg-control { margin-bottom: 6px; }
.fg-control-name { font-size: 12px; color: #333; display: flex; align-items: center;
  justify-content: space-between; }
.fg-status { font: 13px sans-serif; margin-left: 12px; white-space: nowrap; overflow: hidden;
  text-overflow: ellipsis; }
.fg-status.bad { color: #b00020; }
"""


# Monaco is most of the page's script (4 MB of trame-code's 7 MB), and nothing of the first
# picture needs it: the page starts without it and loads it once the model is drawn, by
# hand as trame would have (its style, its script, then Vue.use on trame's app: a component
# registered late is found when the v-if that holds it renders).
EDITOR_LOADER = """
// the first WebGL draw call of the page (this runs before the 3-D view makes its context)
window.fgDrawn = false;
window.fgOnDraw = [];
(() => {
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (type, ...rest) {
    const ctx = getContext.call(this, type, ...rest);
    if (ctx && /webgl/.test(type) && !ctx.fgWatched) {
      ctx.fgWatched = true;
      for (const f of ['drawArrays', 'drawElements']) {
        const draw = ctx[f].bind(ctx);
        ctx[f] = (...a) => {
          const out = draw(...a);
          if (!window.fgDrawn) {
            window.fgDrawn = true;
            setTimeout(() => window.fgOnDraw.splice(0).forEach((g) => g()), 0);
          }
          return out;
        };
      }
    }
    return ctx;
  };
})();
window.fgAfterDraw = function (fn, most) {  // after the first draw, or ``most`` ms at most
  if (window.fgDrawn) return setTimeout(fn, 0);
  window.fgOnDraw.push(fn);
  setTimeout(fn, most);
};
window.fgLoadEditor = function (files, ready) {  // files: {styles, scripts, use}
  if (window.fgEditorAsked) return;
  window.fgEditorAsked = true;
  for (const href of files.styles) {
    const css = document.createElement('link');
    css.rel = 'stylesheet';
    css.href = href;
    document.head.appendChild(css);
  }
  const next = (i) => {
    if (i < files.scripts.length) {
      const js = document.createElement('script');
      js.src = files.scripts[i];
      js.onload = () => next(i + 1);
      document.head.appendChild(js);
      return;
    }
    for (const [name, ...options] of files.use) window.trame.app.use(window[name], ...options);
    ready();
  };
  next(0);
};
"""


# How a step's arrays reach vtk.js (this runs before the 3-D view is set up). trame's client
# reads each binary websocket message as a Blob, whose bytes the browser hands back
# asynchronously, and wraps each array vtk.js asks for in a Blob again (read with a
# FileReader): some 20 ms of the page's time for a step of the spiral tube, and a wait
# for each read. Here the websocket delivers ArrayBuffers instead (its binaryType is set
# when trame's client first sends on it, and each message reaches wslink's reader through
# a Chunk, the part of the Blob interface it uses); the arrays a step sends ahead of its
# scene (formgraph.studio.scene.ARRAYS_TOPIC) are kept by hash until vtk.js asks for them,
# and any other array is asked for as before, its bytes handed on as an ArrayBuffer.
ARRAYS = """
(() => {
  class Chunk {  // what wslink's client reads of a message: size, slice, arrayBuffer
    constructor(buffer, start = 0, end = buffer.byteLength) {
      this.buffer = buffer;
      this.start = start;
      this.end = end;
    }
    get size() { return this.end - this.start; }
    slice(a = 0, b = this.size) {
      const n = this.size;
      const at = (i) => Math.min(Math.max(i < 0 ? n + i : i, 0), n);
      const lo = at(a);
      return new Chunk(this.buffer, this.start + lo, this.start + Math.max(lo, at(b)));
    }
    arrayBuffer() {
      const whole = this.start === 0 && this.end === this.buffer.byteLength;
      return Promise.resolve(whole ? this.buffer : this.buffer.slice(this.start, this.end));
    }
  }
  const asBuffer = (data) => {  // msgpack's bytes (a view) as an ArrayBuffer of their own
    if (!data || !(data.buffer instanceof ArrayBuffer)) return data;  // text: base64
    const whole = data.byteOffset === 0 && data.byteLength === data.buffer.byteLength;
    return whole ? data.buffer
      : data.buffer.slice(data.byteOffset, data.byteOffset + data.byteLength);
  };
  const sent = new Map();  // hash -> ArrayBuffer, until vtk.js asks for it
  let held = 0;  // their bytes
  const client = window.trame && window.trame.client;
  const session = client && client.getConnection && client.getConnection().getSession();
  if (!session || !client.registerProtocol) return;  // (the arrays are then asked for)
  // (installed only now that trame's client is known to be the one reading its messages)
  const send = WebSocket.prototype.send;
  WebSocket.prototype.send = function (data) {
    // only trame's own socket (its /ws route; any other on the page is left as it is), and
    // not one that reads ArrayBuffers itself or has no handler yet
    if (!this.fgBuffers && this.binaryType === 'blob' && typeof this.onmessage === 'function'
        && new URL(this.url).pathname.endsWith('/ws')) {
      this.fgBuffers = true;
      const handle = this.onmessage;
      this.binaryType = 'arraybuffer';
      this.onmessage = (event) => handle(
        event.data instanceof ArrayBuffer ? {data: new Chunk(event.data)} : event);
    }
    return send.call(this, data);
  };
  session.subscribe('%(topic)s', ([arrays]) => {
    for (const [hash, data] of Object.entries(arrays)) {
      const buffer = asBuffer(data);
      if (sent.has(hash)) held -= sent.get(hash).byteLength || 0;
      sent.set(hash, buffer);
      held += buffer.byteLength || 0;
    }
    // (the oldest first) at most 64 arrays and 256 MiB: those vtk.js never asks for go too
    while (sent.size > 64 || (held > 256 * 2 ** 20 && sent.size > 1)) {
      const oldest = sent.keys().next().value;
      held -= sent.get(oldest).byteLength || 0;
      sent.delete(oldest);
    }
  });
  client.registerProtocol('SyncView', (s) => ({  // trame's own, but for getArray
    getArray(hash, binary = true) {
      if (sent.has(hash)) {
        const buffer = sent.get(hash);
        sent.delete(hash);
        held -= buffer.byteLength || 0;
        return Promise.resolve(buffer);
      }
      return s.call('viewport.geometry.array.get', [hash, binary]).then(asBuffer);
    },
    getViewState(id, fresh = false) {
      return s.call('viewport.geometry.view.get.state', [id, fresh]);
    },
    addViewObserver(id) { return s.call('viewport.geometry.view.observer.add', [id]); },
    removeViewObserver(id) { return s.call('viewport.geometry.view.observer.remove', [id]); },
    subscribeToViewChange(fn) {
      return s.subscribe('viewport.geometry.view.subscription', fn);
    },
    unsubscribe(subscription) { return s.unsubscribe(subscription); },
  }));
})();
"""


def clickable_svg(drawing: Any) -> str:
    """The drawing's SVG with an invisible rectangle over each node box, ``data-node`` set
    to the node's name (the page's click handler reads it)."""
    from xml.sax.saxutils import quoteattr

    boxes = []
    rect = None
    for shape in drawing.shapes:
        cls = getattr(shape, "cls", "")
        if cls == "node":
            rect = shape
        elif cls == "param":
            rect = None
        elif cls == "name" and rect is not None:
            boxes.append((shape.text, rect))
            rect = None
    hits = "".join(
        f'<rect data-node={quoteattr(name)} x="{r.x:.1f}" y="{r.y:.1f}" width="{r.w:.1f}" '
        f'height="{r.h:.1f}" fill="transparent" stroke="none"/>'
        for name, r in boxes
    )
    svg = drawing.svg
    svg = svg[svg.index("<svg") :]  # no XML declaration inside a page
    return svg.replace("</svg>", hits + "</svg>")


def build(page: Any) -> tuple[Any, Any]:
    """The page's widgets, bound to ``page``'s state and controller: (layout, 3-D view)."""
    from trame.ui.vuetify3 import VAppLayout
    from trame.widgets import client, code, html
    from trame.widgets import vuetify3 as v
    from trame_pyvista.widgets import PyVistaLocalView

    from .scene import ARRAYS_TOPIC

    page.state.editor_ready = False
    with VAppLayout(page.server, full_height=True) as layout:
        client.Style(CSS)
        client.Script(EDITOR_LOADER)
        client.Script(ARRAYS % {"topic": ARRAYS_TOPIC})
        ready = "() => trame.state.set('editor_ready', true)"
        load = f"window.fgLoadEditor(editor_files, {ready})"
        after_draw = f"window.fgAfterDraw(() => {load}, 8000)"
        # the first picture drawn (or sent and given 8 s to draw: a result with nothing to
        # draw), or the first problem shown: the editor's turn
        client.ClientStateChange(
            value="status_bad", change=f"status_bad && {load}", trigger_on_create=True
        )
        client.ClientStateChange(
            value="cook_id",
            change=f"cook_id > 0 && {after_draw}",
            trigger_on_create=True,
        )
        with v.VAppBar(density="compact", flat=True, border=True):
            v.VAppBarTitle(f"{page.session.path.name}", style="flex: 0 0 auto; font-size: 16px;")
            # the editor's text goes with the click: what the page shows is what is saved,
            # even while the text's own state update is still on its way
            v.VBtn(
                "Save", click="trigger('save', [text])", variant="tonal", classes="ml-2", id="save"
            )
            v.VBtn("Run", click=page.ctrl.run, variant="tonal", classes="ml-2", id="run")
            v.VBtn(
                "Reload",
                click=page.ctrl.reload,
                variant="text",
                classes="ml-1",
                id="reload",
                title="read the graph file again (the editor's unsaved edits are lost)",
            )
            html.Div(
                "{{ status }}",
                classes=("status_bad ? 'fg-status bad' : 'fg-status'",),
                id="status",
            )
            v.VSpacer()
            html.Div("{{ JSON.stringify(timing) }}", id="timing", style="display: none")
            v.VProgressCircular(
                v_show=("busy",), indeterminate=True, size=18, width=2, classes="mr-3"
            )
        with v.VMain():
            with html.Div(classes="fg-main"):
                with html.Div(classes="fg-left"):
                    with html.Div(classes="fg-editor", id="editor"):
                        # the text until Monaco (4 MB of script) has loaded, after the
                        # first picture (see EDITOR_LOADER)
                        html.Pre("{{ text }}", v_if="!editor_ready", classes="fg-plain")
                        editor = code.Editor(
                            v_if="editor_ready",
                            v_model=("text",),
                            language="yaml",
                            theme="vs",
                            markers=("markers",),
                            options=("editor_options",),
                        )
                        # resolved by name when it renders: it is registered after the
                        # page's template was compiled
                        editor._elem_name = "component"
                        editor._attributes["is"] = 'is="vs-editor"'
                    with html.Div(classes="fg-problems", id="problems", v_show="problems.length"):
                        html.Div(
                            "{{ p }}",
                            v_for="p in problems",
                            style=("p.startsWith('warning') ? 'color: #8a5a00' : ''",),
                        )
                with html.Div(classes="fg-center"):
                    with html.Div(classes="fg-view", id="view"):
                        view = PyVistaLocalView(
                            page.plotter,
                            after_scene_loaded=f"cook_id > 0 && {after_draw}",
                        )
                    with html.Div(classes="fg-graph", id="graph"):
                        html.Div(
                            "showing {{ shown }}",
                            style="font: 12px sans-serif; padding: 4px 8px; color: #555;",
                        )
                        html.Div(
                            v_html=("graph_svg",),
                            click=(
                                "$event.target.closest('[data-node]') && "
                                "trigger('show_node', [$event.target.closest('[data-node]')"
                                ".getAttribute('data-node')])"
                            ),
                        )
                with html.Div(classes="fg-right", id="controls"):
                    with html.Div(
                        style="display: flex; justify-content: space-between; "
                        "align-items: center; margin-bottom: 4px;"
                    ):
                        html.B("params", style="font: 13px sans-serif;")
                        v.VBtn(
                            "reset all",
                            click=page.ctrl.reset_all,
                            size="x-small",
                            variant="text",
                        )
                    v.VBtn(
                        "show results",
                        click=page.ctrl.show_results,
                        size="x-small",
                        variant="text",
                        block=True,
                        classes="mb-2",
                    )
                    with html.Div(v_show=("frames_n > 0",), classes="fg-control", id="frames"):
                        html.Div(
                            "frame {{ frame_k }} of {{ frames_n }}",
                            classes="fg-control-name",
                            title="the steps of the shown simulated node, from the cache",
                        )
                        v.VSlider(
                            model_value=("frame_k",),
                            min=1,
                            max=("frames_n",),
                            step=1,
                            density="compact",
                            hide_details=True,
                            color="secondary",
                            update_modelValue="frame_k = $event; trigger('show_frame', [$event])",
                            classes="fg-frame-slider",
                        )
                    v.VSelect(
                        v_show=("attributes.length",),
                        label="colour by",
                        items=("colour_items",),
                        model_value=("color_by",),
                        update_modelValue="color_by = $event; trigger('colour_by', [$event])",
                        density="compact",
                        hide_details=True,
                        variant="outlined",
                        classes="mb-3",
                        id="colour-by",
                    )
                    _control_widgets(v, html)
    _defer_editor(page.server)
    return layout, view


def _defer_editor(server: Any) -> None:
    """Take trame-code's scripts, styles and Vue plugin out of what the page loads before
    it starts (they stay served) into ``editor_files``, which :data:`EDITOR_LOADER` loads
    after the first picture."""
    from trame_code.module import serve_directory

    state = server.state
    mine = {"styles": [], "scripts": [], "use": []}
    for key, kind in (("trame__styles", "styles"), ("trame__scripts", "scripts")):
        mine[kind] = [u for u in state[key] if str(u).startswith(serve_directory)]
        state[key] = [u for u in state[key] if not str(u).startswith(serve_directory)]
    kept = []
    for use in state.trame__vue_use:
        name = use[0] if isinstance(use, (list, tuple)) else use
        if name == "trame_code":
            mine["use"].append(list(use) if isinstance(use, (list, tuple)) else [use])
        else:
            kept.append(use)
    state.trame__vue_use = kept
    state.editor_files = mine


def _control_widgets(v: Any, html: Any) -> None:
    """A control per param (``controls`` in the state), with its reset."""
    # the page's value goes to the server's state too (no echo back to this page), so a
    # page loaded later starts from it; the step itself comes with the trigger
    set_value = (
        "params[c.name] = $event; flushState('params'); trigger('set_param', [c.name, $event])"
    )
    with html.Div(v_for="c in controls", key="c.name", classes="fg-control"):
        with html.Div(classes="fg-control-name"):
            html.Span(  # a slider's value to its step's decimals, not 9.399999999999999
                "{{ c.name }} = {{ c.digits == null || typeof params[c.name] !== 'number' "
                "? params[c.name] : params[c.name].toFixed(c.digits) }}",
                title=("c.doc",),
            )
            v.VBtn(
                "reset",
                size="x-small",
                variant="text",
                click="trigger('reset_param', [c.name])",
                disabled=("params[c.name] === c.default",),
            )
        v.VSlider(
            v_if="c.kind === 'slider'",
            model_value=("params[c.name]",),
            min=("c.min",),
            max=("c.max",),
            step=("c.step",),
            density="compact",
            hide_details=True,
            color="primary",
            update_modelValue=set_value,
            classes=("'fg-slider-' + c.name",),
        )
        v.VTextField(
            v_if="c.kind === 'number' || c.kind === 'text'",
            model_value=("params[c.name]",),
            density="compact",
            hide_details=True,
            variant="outlined",
            change=(
                "(v => { params[c.name] = v; flushState('params'); "
                "trigger('set_param', [c.name, v]) })(c.kind === 'number' ? "
                "Number($event.target.value) : $event.target.value)"
            ),
        )
        v.VSwitch(
            v_if="c.kind === 'toggle'",
            model_value=("params[c.name]",),
            density="compact",
            hide_details=True,
            color="primary",
            update_modelValue=set_value,
        )
        v.VSelect(
            v_if="c.kind === 'choice'",
            model_value=("params[c.name]",),
            items=("c.choices",),
            density="compact",
            hide_details=True,
            variant="outlined",
            update_modelValue=set_value,
            classes=("'fg-choice-' + c.name",),
        )
