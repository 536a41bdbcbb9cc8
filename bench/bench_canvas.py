"""The studio's canvas: a gesture as an edit of a 500-node graph file's text, and the drawing.

- Renaming a node wired all along a 500-node chain (read from disk, edited, the new text
  out): ours edits the spans PyYAML's composed nodes locate (:mod:`formgraph.studio.
  textedit`); the reference is ruamel.yaml's round trip as its users write it (load, rename
  the key and the wires to it, dump), which also re-formats what it did not touch.
- The drawing the canvas shows (every port, hit targets), through ``draw_graph``.
- A wire dragged in the studio against a slider step, on the same 500-node chain with a param
  ``dz`` read by its middle node: the wire (the middle node rewired, the edit made on the
  text, the new version checked and cooked) and the slider (``dz`` set) recompute the same
  250 nodes, each time with a fresh ``dz`` so that no cache answers; the graph's drawing,
  which both then redraw, is the row above.
"""

from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

N = 500


def _chain(n: int) -> str:
    lines = ["formgraph: 1", "nodes:", "  n0:", "    type: points.circle", "    count: 8"]
    for i in range(1, n):
        lines += [f"  n{i}:", "    type: geometry.transform", f'    geometry: "@n{i - 1}"']
        lines += ["    translate: [0, 0, 0.01]  # a step up"]
    return "\n".join(lines) + "\n"


def run(table) -> None:
    import formgraph as fg
    from formgraph.drawgraph.layout import draw_graph
    from formgraph.studio import textedit
    from formgraph.studio.canvas import canvas_svg

    folder = Path(tempfile.mkdtemp(prefix="fg-bench-canvas-"))
    path = folder / "chain.yaml"
    path.write_text(_chain(N))
    old, new = f"n{N // 2}", "renamed"

    def ours() -> str:
        text = path.read_text()
        return textedit.apply(text, textedit.rename_node(text, old, new))

    def with_ruamel() -> str:
        from ruamel.yaml import YAML

        yaml = YAML()
        yaml.preserve_quotes = True
        data = yaml.load(path.read_text())
        nodes = data["nodes"]
        at = list(nodes).index(old)
        nodes.insert(at, new, nodes.pop(old))
        for body in nodes.values():
            for key, value in body.items():
                if isinstance(value, str) and (value == f"@{old}" or value.startswith(f"@{old}.")):
                    body[key] = type(value)(f"@{new}{value[len(old) + 1 :]}")
        out = io.StringIO()
        yaml.dump(data, out)
        return out.getvalue()

    text = path.read_text()
    changed = {
        name: sum(a != b for a, b in zip(text.splitlines(), fn().splitlines(), strict=False))
        for name, fn in (("ours", ours), ("ruamel", with_ruamel))
    }
    table.compare(
        f"rename a node of a {N}-node graph file (text to text)",
        api=ours,
        references={"ruamel.yaml round trip": with_ruamel},
        note=f"lines changed: ours {changed['ours']}, ruamel {changed['ruamel']}",
    )
    graph = fg.load(path)
    table.compare(
        f"the canvas's drawing of a {N}-node graph",
        api=lambda: canvas_svg(draw_graph(graph, all_ports=True)),
        rounds=5,
    )
    _edit_against_slider(table, folder)
    for p in folder.iterdir():
        os.remove(p)
    folder.rmdir()


def _edit_against_slider(table, folder: Path) -> None:
    import types

    from formgraph.studio.canvas import Canvas
    from formgraph.studio.session import StudioSession

    mid = N // 2
    text = _chain(N).replace("formgraph: 1\n", "formgraph: 1\nparams:\n  dz: {default: 0.01}\n")
    text = text.replace(
        f'    geometry: "@n{mid - 1}"\n    translate: [0, 0, 0.01]',
        f'    geometry: "@n{mid - 1}"\n    translate: [0, 0, "=dz"]',
    )
    path = folder / "slider.yaml"
    path.write_text(text)
    session = StudioSession(path, out_dir=folder / "out")
    session.show([f"n{N - 1}"])
    assert session.open(text).ok
    canvas = Canvas(types.SimpleNamespace(session=session), bind=False)  # its server half
    state = {"text": text, "dz": 0.01, "from": mid - 1}

    def fresh() -> float:
        state["dz"] += 1e-3
        return state["dz"]

    def wire() -> None:  # as the studio's worker answers the page, then cooks
        state["from"] = mid - 2 if state["from"] == mid - 1 else mid - 1
        reply = canvas.answer(
            0, "wire", [f"n{state['from']}", "", f"n{mid}", "geometry"], state["text"]
        )
        state["text"] = reply["text"]
        session.values["dz"] = fresh()  # (as if the slider had moved since)
        cooked = session.open(state["text"], canvas.take_checked(state["text"]))
        assert cooked.ok and cooked.computed == N - mid, (cooked.message, cooked.computed)

    def slider() -> None:
        cooked = session.set_params(dz=fresh())
        assert cooked.ok and cooked.computed == N - mid, (cooked.message, cooked.computed)

    table.compare(
        f"a wire dragged in the studio on a {N}-node graph ({N - mid} nodes recook)",
        api=wire,
        references={"a slider step (the same nodes recook)": slider},
        rounds=5,
        note="the wire: its edit, checks and cook; the slider: its cook",
    )
