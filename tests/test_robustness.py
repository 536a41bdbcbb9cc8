"""Every node, fed degenerate but well-typed inputs, either works or fails with a clear
GraphError/NodeError: never a raw exception, never a hang."""

from __future__ import annotations

import enum
import random

import numpy as np
import pytest

import formgraph as fg
from formgraph.core.types import Expression, Faces, OutputPath, Vec3
from formgraph.geometry import Curve, Mesh, NurbsCurve, NurbsSurface, Points, Surface

NODE_TYPES = [n for n in fg.node_types() if not n.startswith(("stub.", "bench."))]


@pytest.fixture(scope="module")
def values():
    line = fg.NurbsCurve.polyline([[0, 0], [1, 0]])
    g = fg.Graph()
    g.add("c", "nurbs.circle")
    g.add("b", "mesh.box")
    g.add_param("line", type="Curve")
    g.add("s", "nurbs.extrude", curve="=line")
    out = g.evaluate(["c", "b", "s"], line=line)
    tri = fg.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    return {"line": line, "circle": out["c"], "box": out["b"], "surface": out["s"], "tri": tri}


def samples(kind, v):
    b = kind.base
    if kind.is_list:
        if b in (Curve, NurbsCurve):
            return [[v["line"]], [v["line"], v["circle"]], [v["line"], v["line"]]]
        if b is Points:
            return [[[[0, 0], [1, 0]], [[0, 1], [1, 1]]], [[[0, 0]]]]
        if b is Mesh:
            return [[v["tri"]], [v["box"], v["tri"]]]
        if b is Vec3:
            return [[[0, 0, 0]], [[0, 0, 0], [0, 0, 0]]]
        if b is float:
            return [[0.0, 0.0], [1.0], [-1.0, 2.0]]
        if b is int:
            return [[0], [1]]
        return [[]]
    table = {
        int: [0, 1, 2, 100],
        float: [0.0, -1.0, 1e-12, 1e6],
        bool: [True, False],
        Vec3: [[0, 0, 0], [0, 0, 1], [1e-300, 0, 0]],
        Points: [[[0, 0]], [[0, 0], [0, 0]], [[0, 0], [1, 1], [0, 0]], [[0, 0], [1, 0], [2, 0]]],
        Curve: [v["line"], v["circle"]],
        NurbsCurve: [v["line"], v["circle"]],
        Surface: [v["surface"]],
        NurbsSurface: [v["surface"]],
        Mesh: [v["tri"], v["box"]],
        Faces: [[[0, 1, 2]], [[0, 0, 1]]],
        Expression: ["t", "1/0*t", "sqrt(-1-t)"],
        OutputPath: ["x.out"],
        str: ["a"],
    }
    if isinstance(b, type) and issubclass(b, enum.Enum):
        return [m.value for m in b]
    return table.get(b, [None])


@pytest.mark.parametrize("node_type", NODE_TYPES)
def test_degenerate_inputs_give_clear_errors(node_type, values, tmp_path):
    spec = fg.node_types()[node_type]
    rng = random.Random(node_type)
    for _ in range(25):
        g = fg.Graph(out_dir=tmp_path, budget=2_000_000)
        inputs = {}
        for p in spec.inputs.values():
            if not p.required and rng.random() < 0.5:
                continue
            kind = rng.choice(p.type.kinds)
            v = rng.choice(samples(kind, values))
            if v is None and not p.type.optional:
                continue
            geometry = isinstance(v, fg.geometry.Geometry) or (
                isinstance(v, list) and v and isinstance(v[0], fg.geometry.Geometry)
            )
            if geometry:  # geometry comes in through a typed param, as from Python
                base = (
                    "Curve"
                    if isinstance(v if not isinstance(v, list) else v[0], Curve)
                    else (type(v if not isinstance(v, list) else v[0]).__name__)
                )
                g.add_param(f"p_{p.name}", type=f"list[{base}]" if isinstance(v, list) else base)
                g.set(**{f"p_{p.name}": v})
                inputs[p.name] = f"=p_{p.name}"
            else:
                inputs[p.name] = v
        g.add("n", node_type, **inputs)
        try:
            g.evaluate("n")
        except fg.GraphError as exc:
            assert str(exc)
        except fg.NodeError as exc:
            # a deliberate refusal (ValueError with a sentence), not a bug of ours wrapped up
            cause = exc.__cause__
            assert isinstance(cause, ValueError), f"{node_type}: {exc!r} from {cause!r}"
            assert not isinstance(cause, np.linalg.LinAlgError), f"{node_type}: {exc}"
            assert "operands could not be broadcast" not in str(exc), f"{node_type}: {exc}"
