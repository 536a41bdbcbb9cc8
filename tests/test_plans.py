"""Plans in bulk (``Graph.plans``, what a sweep keys its variants with) against plans one
variant at a time (``Graph.plan``, a fresh run each): the same steps, keys and upstream
keys, over random graphs of every kind of input a key holds (literals, expressions, an
expression port's text, per-element expressions, wires, an input file, an export) and
random sets of varied params; and over every example graph (repeated and subgraph nodes
among them, which are planned variant by variant)."""

from __future__ import annotations

import random
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.core.errors import GraphError

ROOT = Path(__file__).resolve().parents[1]

PARAMS = {"a": (0.1, 10.0), "b": (1, 6), "flag": (False, True)}


def _steps(steps: list) -> list[tuple]:
    return [(s.name, s.key, s.upstream, s.export, s.upstream_keys) for s in steps]


def _graph(choice: dict[str, int], folder: Path) -> fg.Graph:
    """One of many graphs: each port takes a literal or an expression over the params."""

    def pick(port: str, *options: object) -> object:
        return options[choice.get(port, 0) % len(options)]

    g = fg.Graph(out_dir=folder / "out", inputs_dir=folder)
    g.add_param("a", 1.0, min=0.1, max=10.0)
    g.add_param("b", 2, min=1, max=6)
    g.add_param("flag", False)
    g.add(
        "pts",
        "points.circle",
        count=pick("count", 8, "=b + 3"),
        radius=pick("r", 1.5, "=a", "=a * b"),
    )
    g.add(
        "grid", "points.grid", nx=pick("nx", 3, "=b + 1"), ny=2, spacing=pick("sp", 0.5, "=a / 4")
    )
    g.add("ring", "curves.polyline", points="@pts", closed=pick("closed", True, "=flag"))
    g.add(
        "par",
        "curves.parametric",
        x=pick("x", "cos(t)", "a * cos(t)"),  # an expression port: its text and the params it reads
        y="sin(t)",
        samples=pick("samples", 16, "=b * 8"),
    )
    g.add("off", "curves.offset", curve="@ring", distance=pick("dist", 0.1, "=a / 10"))
    g.add(
        "tagged",
        "attr.set",
        geometry="@grid",
        name="h",
        value=pick("value", 2.0, "=x * a", "=i + b"),
    )
    g.add("read", "read.points", path="pts.csv")
    g.add("svg", "export.svg", curves=["@ring", "@off", "@par"], path="c.svg")
    return g


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("plans")
    (d / "pts.csv").write_text("x,y,z\n0,0,0\n1,2,3\n", encoding="utf-8")
    return d


def _value(rng: random.Random, name: str) -> object:
    lo, hi = PARAMS[name]
    if isinstance(lo, bool):
        return rng.random() < 0.5
    if isinstance(lo, int):
        return rng.randint(lo, hi)
    return rng.choice(
        [lo, hi, max(lo, round(rng.uniform(lo, hi), rng.randint(0, 3))), rng.uniform(lo, hi)]
    )


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    choice=st.dictionaries(
        st.sampled_from(["count", "r", "nx", "sp", "closed", "x", "samples", "dist", "value"]),
        st.integers(0, 2),
    ),
    varied=st.sets(st.sampled_from(sorted(PARAMS)), min_size=1),
    count=st.integers(2, 5),
    seed=st.integers(0, 2**31),
    targets=st.sampled_from([["svg"], ["off", "tagged"], ["par", "read", "grid"], ["ring"]]),
)
def test_bulk_keys_equal_each_variant_planned_alone(folder, choice, varied, count, seed, targets):
    g = _graph(choice, folder)
    rng = random.Random(seed)
    variants = [{n: _value(rng, n) for n in sorted(varied)} for _ in range(count)]
    variants.append(dict(variants[0]))  # a repeated variant: the same keys again
    bulk = g.plans(targets, variants)
    alone = [g.plan(targets, **v) for v in variants]
    assert [_steps(p) for p in bulk] == [_steps(p) for p in alone]
    assert _steps(bulk[-1]) == _steps(bulk[0])
    pts = [s.key for p in bulk for s in p if s.name == "pts"]
    if pts and choice.get("r", 0) % 3 and "a" in varied and len({v["a"] for v in variants}) > 1:
        assert len(set(pts)) > 1  # the radius reads a: its key moved with it


def test_a_variant_whose_expression_fails_is_refused_as_alone(folder):
    g = _graph({"r": 2}, folder)  # radius = a * b
    g.add_param("d", 1.0)
    g.add("bad", "points.circle", count=4, radius="=1 / (d - 1)")
    with pytest.raises(GraphError) as alone:
        g.plan(["bad"], d=1.0)
    with pytest.raises(GraphError) as bulk:
        g.plans(["bad", "ring"], [{"d": 2.0}, {"d": 1.0}])
    assert str(bulk.value) == str(alone.value)


@pytest.mark.parametrize("path", sorted((ROOT / "graphs").glob("*.yaml")), ids=lambda p: p.stem)
def test_example_graphs_plan_in_bulk_as_alone(path):
    g = fg.load(path)
    numbers = {
        n: v for n, v in g.params.items() if isinstance(v, (int, float)) and not isinstance(v, bool)
    }
    if not numbers:
        pytest.skip("no number params")
    rng = random.Random(path.stem)
    defs = g.param_defs
    variants = []
    for _ in range(3):
        v = {}
        for n, value in numbers.items():
            lo = defs[n].min if defs[n].min is not None else value - 1
            hi = defs[n].max if defs[n].max is not None else value + 1
            if rng.random() < 0.6:
                v[n] = (
                    rng.randint(int(lo), int(hi)) if isinstance(value, int) else rng.uniform(lo, hi)
                )
        variants.append(v)
    targets = g.sinks()
    assert [_steps(p) for p in g.plans(targets, variants)] == [
        _steps(g.plan(targets, **v)) for v in variants
    ]
