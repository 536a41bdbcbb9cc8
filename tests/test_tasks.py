"""What a sweep's row tasks carry, pickled compactly: each distinct shape of plan once and
per variant its keys and params, the chunk packed once on the client; and what they hand
back, one object per task. Both must come back equal to what was sent."""

from __future__ import annotations

import pickle

from formgraph.evaluation.stats import Step
from formgraph.sweeps.tasks import Packed, RowChunk, RowPlan, RowResult, RowResults


def _plan(i: int, cached: bool = False) -> RowPlan:
    pts = Step("pts", f"k-pts-{i}", (), False, ())
    ring = Step("ring", f"k-ring-{i}", ("pts", "prof"), False, (pts.key, "k-prof"))
    steps = (pts, ring)
    if cached:  # a node the client saw cached: its upstream is not in the plan at all
        steps = (Step("ring", f"k-ring-{i}", ("pts", "prof"), False, (f"k-pts-{i}", "k-prof")),)
    return RowPlan(steps, (("prof", "k-prof"),), {"r": 1.0 + i, "n": i}, f"row-{i}")


def test_a_chunk_of_several_shapes_round_trips():
    plans = (_plan(0), _plan(1, cached=True), _plan(2), RowPlan((), (), {}, "row-empty"))
    chunk = RowChunk(plans, ("k-prof",))
    back = pickle.loads(pickle.dumps(chunk))
    assert back == chunk
    assert Packed.of(chunk).unpack() == chunk
    assert pickle.loads(pickle.dumps(Packed.of(chunk))).unpack() == chunk


def test_the_packed_form_holds_each_shape_once():
    many = RowChunk(tuple(_plan(i) for i in range(200)), ("k-prof",))
    one = RowChunk((_plan(0),), ("k-prof",))
    per_variant = (len(Packed.of(many).data) - len(Packed.of(one).data)) / 199
    assert per_variant < 110  # its keys and params; the names and wires are not repeated
    assert Packed.of(many).__dask_tokenize__() == many.__dask_tokenize__()


def test_results_round_trip_as_one_object():
    rows = [
        (
            f"row-{i}",
            RowResult(None if i else "boom", 0.5 * i, {"m": i}, {}, None, {"k": (0.1, "computed")}),
        )
        for i in range(3)
    ]
    back = pickle.loads(pickle.dumps(RowResults(rows)))
    assert back == RowResults(rows)
    assert isinstance(back.rows[1][1], RowResult)
