"""sweep.csv never carries a spreadsheet formula: a text cell that starts with = + - @ gets
a leading ', numbers stay numbers, and a resumed sweep reads its own cells back."""

from __future__ import annotations

import csv

import pytest
from distributed import Client, LocalCluster

import formgraph as fg
from formgraph.sweeps.api import sweep

HOSTILE = ["=cmd|' /C calc'!A0", "@SUM(1+1)", "+1+1", "-1", "'=x", "plain"]


@pytest.fixture(scope="module")
def client():
    with (
        LocalCluster(
            n_workers=1,
            processes=False,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
            silence_logs=40,
        ) as c,
        Client(c) as cl,
    ):
        yield cl


def test_formula_cells_are_neutralized_and_read_back(tmp_path, client, monkeypatch):
    monkeypatch.chdir(tmp_path)
    f = tmp_path / "=2+5.yaml"
    f.write_text(
        "formgraph: 1\nparams:\n  label: x\n  r: 1.0\nnodes:\n"
        "  c: {type: nurbs.circle, radius: '=r'}\n  m: {type: curves.measure, curve: '@c'}\n"
    )
    g = fg.load("=2+5.yaml")
    out = tmp_path / "out"
    vary = {"label": HOSTILE, "r": [1.0, -1.0]}
    result = sweep(g, vary, ["m.length"], out=out, client=client, cache_dir=None)
    assert result.failed == len(HOSTILE)  # a negative radius: the error cell names the file
    rows = list(csv.reader((out / "sweep.csv").open()))
    header, body = rows[0], rows[1:]
    for row in body:
        for cell in row:
            assert not cell.startswith(("=", "+", "@")), cell
            assert not cell.startswith("-") or float(cell) < 0, cell
    labels = {row[header.index("label")] for row in body}
    assert labels == {"'=cmd|' /C calc'!A0", "'@SUM(1+1)", "'+1+1", "-1", "''=x", "plain"}
    errors = [row[header.index("error")] for row in body if row[header.index("status")] != "ok"]
    assert errors and all(e.startswith("'=2+5.yaml") for e in errors)
    again = sweep(g, vary, ["m.length"], out=out, client=client, cache_dir=None)
    assert again.resumed == len(HOSTILE)  # the ok rows, read back as written
    assert sorted(r["label"] for r in again.rows if r["status"] == "ok") == sorted(HOSTILE)
