// The studio's canvas: the graph's drawing (our own SVG, laid out by formgraph.drawgraph)
// made editable. Every gesture asks the server for an edit of the YAML text, which comes
// back as ranges applied through Monaco (so its undo undoes them); nothing here writes
// the graph itself. Loaded from the package (no network, no build step).
(() => {
  if (window.fgCanvas) return;
  const fg = (window.fgCanvas = {k: 1, tx: 0, ty: 0, seq: 0, sent: {}, selected: null});
  const host = () => document.getElementById('graph-canvas');
  const overlay = () => document.getElementById('fg-overlay');
  const SVGNS = 'http://www.w3.org/2000/svg';

  const editor = () => {
    const ref = window.trame && window.trame.refs && window.trame.refs.editor;
    return ref && ref.editor ? ref.editor : null;
  };
  const text = () => {
    const ed = editor();
    return ed ? ed.getValue() : window.trame.state.get('text');
  };
  const trigger = (name, args) => window.trame.trigger(name, args);

  // ------------------------------------------------------------------ view transform
  // (on the HTML box that holds the drawing, not on its <svg>: a transform set on an SVG
  // root restyles every shape under it, 14,000 of them in a 500-node graph, ~300 ms a step
  // in headless chromium; on the box around it, no shape is restyled)
  const paint = () => {
    const h = host();
    if (!h) return;
    const t = `translate(${fg.tx}px, ${fg.ty}px) scale(${fg.k})`;
    h.querySelectorAll('.fg-drawing, #fg-overlay').forEach((e) => {
      e.style.transform = t;
    });
  };
  fg.paint = paint;
  const toDrawing = (ev) => {
    const r = host().getBoundingClientRect();
    return {x: (ev.clientX - r.left - fg.tx) / fg.k, y: (ev.clientY - r.top - fg.ty) / fg.k};
  };
  const toScreen = (x, y) => ({x: x * fg.k + fg.tx, y: y * fg.k + fg.ty});
  fg.fit = () => {
    const h = host();
    const svg = h && h.querySelector('.fg-drawing svg');
    if (!svg) return;
    const w = +svg.getAttribute('width'), ht = +svg.getAttribute('height');
    // the whole drawing, unless that is too small to read (a long graph: its start)
    const k = Math.max(Math.min(h.clientWidth / w, h.clientHeight / ht, 1.5), 0.35);
    fg.k = k > 0 ? k : 1;
    fg.tx = Math.max((h.clientWidth - w * fg.k) / 2, 0);
    fg.ty = 0;
    paint();
  };

  // ------------------------------------------------------------------------- requests
  const ask = (what, args) => {
    const id = ++fg.seq;
    const t = text();
    fg.sent[id] = t;
    trigger(what, [id, ...args, t]);
    return id;
  };

  fg.reply = (r) => {
    if (!r || r.id === fg.done) return;
    fg.done = r.id;
    const sent = fg.sent[r.id];
    delete fg.sent[r.id];
    if (r.refused) {
      say(r.refused, r.port ? port(r.port[0], r.port[1], 'in') : null);
      return;
    }
    const ed = editor();
    if (ed) {
      if (ed.getValue() !== sent) {  // typed in the meantime: the ranges are of old text
        say('the text changed while the canvas asked; do it again', null);
        return;
      }
      const model = ed.getModel();
      const ops = r.edits.map((e) => ({
        range: {startLineNumber: e.line0, startColumn: e.col0,
                endLineNumber: e.line1, endColumn: e.col1},
        text: e.text, forceMoveMarkers: true,
      }));
      ed.pushUndoStop();
      ed.executeEdits('canvas', ops);
      ed.pushUndoStop();
      if (model.getValue() !== r.text) model.setValue(r.text);  // (never seen: a safety net)
    } else {
      window.trame.state.set('text', r.text);
    }
    clearSay();
  };

  // a sentence shown where it applies (a refused wire: at the port), and in the status
  const say = (message, at) => {
    clearSay();
    const h = host();
    const div = document.createElement('div');
    div.className = 'fg-refusal';
    div.textContent = message;
    if (at) {
      const r = at.getBoundingClientRect(), hr = h.getBoundingClientRect();
      div.style.left = `${r.left - hr.left + 10}px`;
      div.style.top = `${r.top - hr.top + 10}px`;
    } else {
      div.style.left = '8px';
      div.style.top = '28px';
    }
    h.appendChild(div);
    fg.sayTimer = setTimeout(clearSay, 8000);
  };
  const clearSay = () => {
    clearTimeout(fg.sayTimer);
    document.querySelectorAll('.fg-refusal').forEach((e) => e.remove());
  };
  const port = (node, name, kind) => host().querySelector(kind === 'in'
    ? `[data-in="${CSS.escape(node)}"][data-port="${CSS.escape(name)}"]`
    : `[data-out="${CSS.escape(node)}"][data-output="${CSS.escape(name)}"]`);

  // -------------------------------------------------------------------------- gestures
  let drag = null;
  const line = (x0, y0, x1, y1, dashed) => {
    const o = overlay();
    o.innerHTML = '';
    const p = document.createElementNS(SVGNS, 'path');
    const dx = Math.max(Math.abs(x1 - x0) / 2, 8);
    p.setAttribute('d', `M${x0},${y0} C${x0 + dx},${y0} ${x1 - dx},${y1} ${x1},${y1}`);
    p.setAttribute('class', dashed ? 'fg-ghost-wire' : 'fg-ghost-wire ok');
    o.appendChild(p);
  };
  const ghost = (x, y, w, h) => {
    const o = overlay();
    o.innerHTML = '';
    const r = document.createElementNS(SVGNS, 'rect');
    Object.entries({x, y, width: w, height: h, rx: 5, class: 'fg-ghost-box'})
      .forEach(([k, v]) => r.setAttribute(k, v));
    o.appendChild(r);
  };
  const select = (sel) => {
    fg.selected = sel;
    const h = host();
    h.querySelectorAll('.fg-selected').forEach((e) => e.classList.remove('fg-selected'));
    if (!sel) return;
    const q = sel.kind === 'node' ? `[data-node="${CSS.escape(sel.name)}"]`
      : `path[data-from="${CSS.escape(sel.from)}"][data-to="${CSS.escape(sel.to)}"]`;
    h.querySelectorAll(q).forEach((e) => e.classList.add('fg-selected'));
  };
  fg.reselect = () => select(fg.selected);  // after a new drawing

  const down = (ev) => {
    const h = host();
    if (ev.button !== 0 || ev.target.closest('.fg-palette, .fg-rename')) return;
    h.focus({preventScroll: true});
    const at = toDrawing(ev);
    const out = ev.target.closest('[data-out]');
    const node = ev.target.closest('[data-node]');
    const wire = ev.target.closest('path[data-from]');
    if (out) {
      drag = {kind: 'wire', from: out.dataset.out, output: out.dataset.output || '',
              x0: +out.getAttribute('cx'), y0: +out.getAttribute('cy')};
    } else if (node) {
      drag = {kind: 'node', name: node.dataset.node, at, moved: false,
              x: +node.getAttribute('x'), y: +node.getAttribute('y'),
              w: +node.getAttribute('width'), h: +node.getAttribute('height')};
    } else if (wire) {
      select({kind: 'wire', from: wire.dataset.from, to: wire.dataset.to});
      return;
    } else {
      drag = {kind: 'pan', sx: ev.clientX, sy: ev.clientY, tx: fg.tx, ty: fg.ty};
      select(null);
    }
    h.setPointerCapture(ev.pointerId);
    ev.preventDefault();
  };
  const move = (ev) => {
    fg.pointer = toDrawing(ev);
    if (!drag) return;
    if (drag.kind === 'pan') {
      fg.tx = drag.tx + ev.clientX - drag.sx;
      fg.ty = drag.ty + ev.clientY - drag.sy;
      paint();
    } else if (drag.kind === 'wire') {
      const p = fg.pointer;
      line(drag.x0, drag.y0, p.x, p.y, true);
    } else if (drag.kind === 'node') {
      const p = fg.pointer;
      const dx = p.x - drag.at.x, dy = p.y - drag.at.y;
      if (!drag.moved && Math.hypot(dx, dy) * fg.k < 4) return;
      drag.moved = true;
      ghost(drag.x + dx, drag.y + dy, drag.w, drag.h);
    }
  };
  const up = (ev) => {
    const d = drag;
    drag = null;
    overlay().innerHTML = '';
    if (!d) return;
    if (d.kind === 'wire') {
      const hit = document.elementFromPoint(ev.clientX, ev.clientY);
      const target = hit && hit.closest('[data-in]');
      if (target) {
        ask('canvas_wire', [d.from, d.output, target.dataset.in, target.dataset.port]);
      }
    } else if (d.kind === 'node') {
      if (d.moved) {
        const p = toDrawing(ev);
        const x = Math.max(0, Math.round(d.x + p.x - d.at.x));
        const y = Math.max(0, Math.round(d.y + p.y - d.at.y));
        ask('canvas_move', [d.name, x, y]);
      } else {
        // a second click on the node soon after: a double click (the drawing may have
        // been put in anew between the two, so the browser's own dblclick is not used)
        const now = performance.now();
        const again = fg.lastClick && fg.lastClick.name === d.name
          && now - fg.lastClick.t < 450;
        fg.lastClick = again ? null : {name: d.name, t: now};
        select({kind: 'node', name: d.name});
        if (again) opened(d.name);
        else trigger('show_node', [d.name]);
      }
    }
  };
  const wheel = (ev) => {
    ev.preventDefault();
    const r = host().getBoundingClientRect();
    const sx = ev.clientX - r.left, sy = ev.clientY - r.top;
    const k = Math.min(4, Math.max(0.1, fg.k * Math.exp(-ev.deltaY * 0.0015)));
    fg.tx = sx - (sx - fg.tx) * (k / fg.k);
    fg.ty = sy - (sy - fg.ty) * (k / fg.k);
    fg.k = k;
    paint();
  };
  const opened = (name) => {  // a double click: a subgraph's file, any other's name
    const node = host().querySelector(`[data-node="${CSS.escape(name)}"]`);
    if (node && node.dataset.subgraph) trigger('open_subgraph', [name]);
    else if (node && !node.dataset.param) rename(name);
  };
  const key = (ev) => {
    if (ev.target.closest('.fg-palette, .fg-rename')) return;
    const sel = fg.selected;
    if (ev.key === 'Tab' || (ev.key === 'A' && ev.shiftKey)) {
      ev.preventDefault();
      palette();
    } else if ((ev.key === 'Delete' || ev.key === 'Backspace') && sel) {
      ev.preventDefault();
      if (sel.kind === 'node') ask('canvas_delete', [sel.name]);
      else ask('canvas_unwire', [sel.from, sel.to]);
      select(null);
    } else if (ev.key === 'F2' && sel && sel.kind === 'node') {
      ev.preventDefault();
      rename(sel.name);
    } else if ((ev.ctrlKey || ev.metaKey) && (ev.key === 'z' || ev.key === 'Z')) {
      const ed = editor();  // the editor's own undo: a canvas edit is one of its edits
      if (ed) {
        ev.preventDefault();
        ed.trigger('canvas', ev.shiftKey ? 'redo' : 'undo', null);
      }
    } else if (ev.key === 'f' || ev.key === 'Home') {
      fg.fit();
    }
  };

  // --------------------------------------------------------------------- rename
  const rename = (name) => {
    const h = host();
    const rect = h.querySelector(`[data-node="${CSS.escape(name)}"]`);
    if (!rect) return;
    const input = document.createElement('input');
    input.className = 'fg-rename';
    input.value = name;
    const s = toScreen(+rect.getAttribute('x'), +rect.getAttribute('y'));
    input.style.left = `${s.x}px`;
    input.style.top = `${s.y}px`;
    h.appendChild(input);
    input.focus();
    input.select();
    let done = false;
    const finish = (commit) => {
      if (done) return;
      done = true;
      const value = input.value.trim();
      input.remove();
      h.focus({preventScroll: true});
      if (commit && value && value !== name) {
        ask('canvas_rename', [name, value]);
        if (fg.selected && fg.selected.name === name) fg.selected = {kind: 'node', name: value};
      }
    };
    input.addEventListener('keydown', (ev) => {
      ev.stopPropagation();
      if (ev.key === 'Enter') finish(true);
      if (ev.key === 'Escape') finish(false);
    });
    input.addEventListener('blur', () => finish(false));
  };

  // --------------------------------------------------------------------- palette
  const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({'&': '&amp;', '<': '&lt;',
    '>': '&gt;', '"': '&quot;'}[c]));
  const matches = (types, q) => {
    const terms = q.toLowerCase().split(/\s+/).filter(Boolean);
    const scored = [];
    for (const t of types) {
      const name = t.name.toLowerCase(), doc = t.summary.toLowerCase();
      if (!terms.every((w) => name.includes(w) || doc.includes(w))) continue;
      const score = terms.reduce((s, w) => s + (name.startsWith(w) ? 0 : name.includes(w)
        ? 1 : 3), 0);
      scored.push([score, t]);
    }
    scored.sort((a, b) => a[0] - b[0] || (a[1].name < b[1].name ? -1 : 1));
    return scored.slice(0, 60).map((s) => s[1]);
  };
  const palette = () => {
    const h = host();
    h.querySelectorAll('.fg-palette').forEach((e) => e.remove());
    const types = window.trame.state.get('palette') || [];
    const at = fg.pointer || toDrawing({clientX: h.getBoundingClientRect().left + 40,
                                        clientY: h.getBoundingClientRect().top + 40});
    const box = document.createElement('div');
    box.className = 'fg-palette';
    box.innerHTML = '<input placeholder="node type: search names and docs">'
      + '<div class="fg-palette-body"><div class="fg-palette-list"></div>'
      + '<div class="fg-palette-doc"></div></div>';
    h.appendChild(box);
    const input = box.querySelector('input');
    const list = box.querySelector('.fg-palette-list');
    const doc = box.querySelector('.fg-palette-doc');
    let shown = [], hi = 0;
    const render = () => {
      shown = matches(types, input.value);
      hi = Math.min(hi, Math.max(shown.length - 1, 0));
      list.innerHTML = shown.map((t, i) => `<div class="fg-palette-item${i === hi ? ' hi' : ''}"`
        + ` data-type="${esc(t.name)}"><b>${esc(t.name)}</b> <span>${esc(t.summary)}</span>`
        + '</div>').join('') || '<div class="fg-palette-none">no node type matches</div>';
      const t = shown[hi];
      doc.innerHTML = t ? `<b>${esc(t.name)}</b><p>${esc(t.summary)}</p><div>inputs</div><ul>`
        + t.inputs.map((p) => `<li>${esc(p.name)}: ${esc(p.type)}${p.required
          ? ' <i>(required)</i>' : ''}</li>`).join('')
        + '</ul><div>outputs</div><ul>'
        + t.outputs.map((p) => `<li>${esc(p.name || '->')}: ${esc(p.type)}</li>`).join('')
        + '</ul>' : '';
      const el = list.querySelector('.hi');
      if (el) el.scrollIntoView({block: 'nearest'});
    };
    const close = () => { box.remove(); h.focus({preventScroll: true}); };
    const add = (t) => {
      close();
      if (t) ask('canvas_add', [t.name, Math.round(at.x), Math.round(at.y)]);
    };
    input.addEventListener('input', () => { hi = 0; render(); });
    input.addEventListener('keydown', (ev) => {
      ev.stopPropagation();
      if (ev.key === 'ArrowDown') { hi = Math.min(hi + 1, shown.length - 1); render(); }
      else if (ev.key === 'ArrowUp') { hi = Math.max(hi - 1, 0); render(); }
      else if (ev.key === 'Enter') add(shown[hi]);
      else if (ev.key === 'Escape' || ev.key === 'Tab') { ev.preventDefault(); close(); }
    });
    list.addEventListener('mousedown', (ev) => {
      const item = ev.target.closest('[data-type]');
      if (item) { ev.preventDefault(); add(types.find((t) => t.name === item.dataset.type)); }
    });
    render();
    input.focus();
  };
  fg.palette = palette;

  // ----------------------------------------------------------------------- install
  fg.install = () => {
    const h = host();
    if (!h || h.fgInstalled) return;
    h.fgInstalled = true;
    h.tabIndex = 0;
    h.addEventListener('pointerdown', down);
    h.addEventListener('pointermove', move);
    h.addEventListener('pointerup', up);
    h.addEventListener('wheel', wheel, {passive: false});
    h.addEventListener('keydown', key);
    paint();
  };
  // after each drawing of the graph: the overlay in place, the first one fitted to the view
  fg.drawn = () => {
    const h = host();
    if (!h) return;
    fg.install();
    if (!overlay()) {
      const o = document.createElementNS(SVGNS, 'svg');
      o.setAttribute('id', 'fg-overlay');
      o.setAttribute('width', '1');
      o.setAttribute('height', '1');
      h.appendChild(o);
    }
    if (!fg.fitted && h.querySelector('.fg-drawing svg') && h.clientWidth > 0) {
      fg.fitted = true;
      fg.fit();
    }
    paint();
    fg.reselect();
  };
  fg.later = () => setTimeout(fg.drawn, 0);  // (once Vue has put the new drawing in)
  const wait = setInterval(() => {
    if (host()) { clearInterval(wait); fg.drawn(); }
  }, 100);
})();
