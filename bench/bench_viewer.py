"""Viewer: what one slider step costs, redrawn in place, against rebuilding the picture.

Both sides render off screen at 640 x 480. The graph: a 100 x 100 grid of points that a
``height`` param moves, a 512-corner ring and its outline that it does not reach (cached).
Each step changes ``height``, so the grid really recomputes.
"""

from __future__ import annotations

import itertools

import formgraph as fg


def _graph() -> fg.Graph:
    g = fg.Graph()
    g.add_param("height", 1.0, min=0.1, max=100.0)
    g.add("grid", "points.grid", nx=100, ny=100, spacing=[0.1, 0.1, "=height"])
    g.add("ring", "points.circle", count=512, radius=6.0)
    g.add("outline", "curves.polyline", points="@ring", closed=True)
    return g


def run(table) -> None:
    import pyvista as pv

    from formgraph.viewer import Session

    pv.OFF_SCREEN = True
    size = [640, 480]
    case = "slider step: 10k points recomputed, 512-gon cached"

    g = _graph()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    session = Session(g, plotter=plotter)
    session.add_sliders()
    steps = itertools.count(1)

    def in_place() -> None:
        assert session.apply_params(height=1.0 + next(steps) * 1e-6)

    g2 = _graph()
    steps2 = itertools.count(1)

    def rebuild() -> None:
        outs = g2.evaluate(["grid", "outline"], height=1.0 + next(steps2) * 1e-6)
        p = pv.Plotter(off_screen=True, window_size=size)
        p.add_mesh(outs["grid"].to_pyvista(), render_points_as_spheres=True, point_size=12)
        p.add_mesh(outs["outline"].to_pyvista(), line_width=3.5)
        p.show_bounds()
        p.render()
        p.close()

    table.compare(
        case,
        api=in_place,
        references={"pyvista rebuild": rebuild},
        rounds=5,
        note="Session.apply_params, actors updated in place",
        notes={"pyvista rebuild": "the same graph evaluated, a new plotter per step"},
    )
    plotter.close()

    _graph_drawing(table)


def _graph_drawing(table) -> None:
    """Drawing the largest example graph: ours (SVG, and PNG through Pillow) against
    networkx's layered layout drawn by matplotlib (plain circles and arrows, no text boxes)."""
    import io
    from pathlib import Path

    import networkx as nx

    graphs = Path(__file__).resolve().parents[1] / "graphs"
    largest = max(graphs.glob("*.yaml"), key=lambda p: len(fg.load(p).nodes))
    g = fg.load(largest)
    case = f"drawing the graph of {largest.name} ({len(g.nodes)} nodes, {len(g.params)} params)"

    def reference() -> None:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        dag = nx.DiGraph()
        for name in g.nodes:
            dag.add_node(name)
            for up in g._nodes[name].upstream():
                dag.add_edge(up, name)
        for i, gen in enumerate(nx.topological_generations(dag)):
            for n in gen:
                dag.nodes[n]["layer"] = i
        pos = nx.multipartite_layout(dag, subset_key="layer")
        fig, ax = plt.subplots(figsize=(12, 6))
        nx.draw_networkx(dag, pos, ax=ax, node_shape="s", font_size=8)
        buf = io.BytesIO()
        fig.savefig(buf, format="svg")
        plt.close(fig)

    table.compare(
        case,
        api=lambda: fg.draw_graph(g).svg,
        references={
            "formgraph PNG (Pillow, 2x)": lambda: fg.draw_graph(g).png(),
            "networkx + matplotlib SVG": reference,
        },
        rounds=5,
        note="layout + SVG text",
        notes={"networkx + matplotlib SVG": "multipartite layout, circles, no text boxes"},
    )
