"""Which variants a sweep runs: SPEC text, domains checked against params, and sampling."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import formgraph as fg
from formgraph.sweeps.api import progress_text
from formgraph.sweeps.sampling import Domain, domain, parse_spec, sample


def graph() -> fg.Graph:
    return fg.Graph.from_text(
        """
formgraph: 1
params:
  n: {default: 5, min: 3, max: 12}
  r: {default: 1.0, min: 0.5, max: 4}
  closed: false
  spacing: uniform
  label: plain text
nodes:
  pts: {type: points.circle, count: "=n", radius: "=r"}
  c: {type: curves.catmull_rom, points: "@pts", closed: "=closed", spacing: "=spacing"}
""",
        file="g.yaml",
    )


@pytest.mark.parametrize(
    "text, kind, values",
    [
        ("1:5", int, (1, 2, 3, 4, 5)),
        ("0.5:2:4", float, (0.5, 1.0, 1.5, 2.0)),
        ("1:9:5", int, (1, 3, 5, 7, 9)),
        ("1,2,5", int, (1, 2, 5)),
        ("1, 2.5", float, (1.0, 2.5)),
        ("true,no", bool, (True, False)),
        ("a, b", str, ("a", "b")),
        ("7", int, (7,)),
    ],
)
def test_spec_text(text, kind, values):
    d = parse_spec(text, kind)
    assert d.values == values
    assert all(type(v) is kind for v in d.values)


def test_a_float_range_without_a_count_is_an_interval():
    d = parse_spec("0.5:2", float)
    assert (d.values, d.low, d.high) == (None, 0.5, 2.0)


@pytest.mark.parametrize(
    "text, kind, message",
    [
        ("1:2:4", int, "not whole numbers"),
        ("5:1", int, "runs backwards"),
        ("1:2:3:4", float, "not a range"),
        ("1,,2", int, "empty item"),
        ("1.5,2", int, "'1.5' is not a whole number"),
        ("0:1", bool, "a range '0:1' is for number params"),
        ("maybe", bool, "'maybe' is not true or false"),
        ("1:2:0", float, "the count must be 1"),
    ],
)
def test_bad_spec_text(text, kind, message):
    with pytest.raises(ValueError, match=message):
        parse_spec(text, kind)


def test_domains_are_checked_against_the_params():
    g = graph()
    assert domain(g, "n", range(3, 6)).values == (3, 4, 5)
    assert domain(g, "r", [1, 2]).values == (1.0, 2.0)  # ints read as the float param's
    assert domain(g, "spacing", "uniform,chordal").values == ("uniform", "chordal")
    assert domain(g, "label", "a,b").values == ("a", "b")  # text feeding no enum: anything
    cases = [
        ("n", "2:4", "g.yaml:4: param 'n': vary n=2:4: goes down to 2, below the param's min 3"),
        ("r", "1:5:3", "vary r=1:5:3: reaches 5, above the param's max 4"),
        ("n", [4, 4.5], "param 'n': vary n=[4, 4.5]: expected int"),
        ("spacing", "uniform,curly", "'curly' is not one of its choices uniform, centripetal"),
        ("m", "1:2", "g.yaml: vary: unknown param 'm'; params are n, r, closed, spacing, label"),
    ]
    for name, spec, message in cases:
        with pytest.raises(fg.ParamError, match=re.escape(message)):
            domain(g, name, spec)


def test_grid_order_and_refusals():
    a, b = Domain("a", (1, 2)), Domain("b", ("x", "y", "z"))
    assert sample([a, b]) == [{"a": i, "b": s} for i in (1, 2) for s in "xyz"]
    with pytest.raises(ValueError, match="a grid needs values for 'c': give a count, 0:1:N"):
        sample([a, Domain("c", None, 0.0, 1.0, "0:1")])
    with pytest.raises(ValueError, match="more than 1,000,000"):
        sample([Domain("a", tuple(range(1000)))] * 3)
    with pytest.raises(ValueError, match="samples is for the random and lhs methods"):
        sample([a], "grid", 5)
    with pytest.raises(ValueError, match="method lhs needs a sample count"):
        sample([a], "lhs")


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 60), seed=st.integers(0, 2**32 - 1), k=st.integers(1, 7))
def test_latin_hypercube_puts_one_sample_in_each_stratum(n, seed, k):
    x = Domain("x", None, -1.0, 3.0)
    y = Domain("y", tuple(range(k * n)))  # k values per stratum
    rows = sample([x, y], "lhs", n, seed)
    assert rows == sample([x, y], "lhs", n, seed)  # seeded: reproducible
    strata_x = np.floor((np.array([r["x"] for r in rows]) + 1.0) / 4.0 * n).astype(int)
    strata_y = np.array([r["y"] for r in rows]) // k
    assert sorted(strata_x) == list(range(n))
    assert sorted(strata_y) == list(range(n))


def test_random_sampling_is_seeded_and_stays_in_the_domain():
    d = [Domain("x", None, 2.0, 3.0), Domain("c", ("a", "b"))]
    rows = sample(d, "random", 500, seed=7)
    assert rows == sample(d, "random", 500, seed=7) != sample(d, "random", 500, seed=8)
    xs = np.array([r["x"] for r in rows])
    assert xs.min() >= 2.0 and xs.max() < 3.0
    assert {r["c"] for r in rows} == {"a", "b"}


def test_progress_text():
    assert progress_text(3, 10, 1, 0.0) == "sweep 3/10 done, 1 failed"
    assert progress_text(37, 200, 2, 4.0) == "sweep 37/200 done, 2 failed, 4.0/s, ETA 0:40"


def test_the_progress_line_shows_on_a_terminal_only():
    import io

    from formgraph.sweeps.api import TerminalProgress

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    term, pipe = Terminal(), io.StringIO()
    for stream in (term, pipe):
        line = TerminalProgress(stream)
        line(4, 4, 1, 2.0)
        line.clear()
    assert term.getvalue() == "\r\x1b[Ksweep 4/4 done, 1 failed, 2.0/s, ETA 0:00\r\x1b[K"
    assert pipe.getvalue() == ""
