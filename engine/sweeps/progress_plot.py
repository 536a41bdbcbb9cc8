"""``progress.png`` of an optimisation study, drawn with matplotlib (off-screen, Agg).

One objective: every trial's value by trial number and the best feasible value so far.
Two: every trial in the objectives' plane and the Pareto front joined up. More: parallel
coordinates (Inselberg, "The plane with parallel coordinates", The Visual Computer 1(2),
1985), each objective scaled to [0, 1] over the trials, the front drawn on top.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .objectives import Objective

__all__ = ["draw_progress"]

FRONT = "#d62728"
FEASIBLE = "#1f77b4"
INFEASIBLE = "#bbbbbb"


def _label(o: Objective) -> str:
    return f"{o.column} ({'max' if o.maximize else 'min'})"


def draw_progress(
    rows: Sequence[Mapping[str, Any]], objectives: Sequence[Objective], path: Path
) -> Path:
    """Draw the study's ``rows`` (trial order) to ``path`` atomically; returns the path."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    ok = [r for r in rows if r["status"] == "ok"]
    values = np.array([[r[o.column] for o in objectives] for r in ok], dtype=np.float64)
    values = values.reshape(len(ok), len(objectives))
    trial = np.array([r["trial"] for r in ok], dtype=np.int64)
    feasible = np.array([bool(r["feasible"]) for r in ok], dtype=bool)
    front = np.array([bool(r["pareto"]) for r in ok], dtype=bool)
    fig = Figure(figsize=(7, 4.5), dpi=110, layout="constrained")
    ax = fig.add_subplot()
    failed = len(rows) - len(ok)
    title = f"{len(rows)} trials, {int(feasible.sum())} feasible" + (
        f", {failed} failed" if failed else ""
    )
    if len(objectives) == 1:
        o = objectives[0]
        v = values[:, 0]
        bad = ~feasible
        ax.scatter(trial[bad], v[bad], s=12, c=INFEASIBLE, marker="x", label="infeasible")
        ax.scatter(trial[feasible], v[feasible], s=12, c=FEASIBLE, label="feasible")
        if feasible.any():
            masked = np.where(feasible, v if not o.maximize else -v, np.inf)
            best = np.minimum.accumulate(masked)
            best = best if not o.maximize else -best
            ax.step(trial, best, where="post", c=FRONT, lw=2, label="best so far")
        ax.set_xlabel("trial")
        ax.set_ylabel(_label(o))
    elif len(objectives) == 2:
        x, y = values[:, 0], values[:, 1]
        ax.scatter(x[~feasible], y[~feasible], s=12, c=INFEASIBLE, marker="x", label="infeasible")
        ax.scatter(x[feasible & ~front], y[feasible & ~front], s=14, c=FEASIBLE, label="feasible")
        order = np.argsort(x[front])
        ax.plot(x[front][order], y[front][order], "-o", c=FRONT, ms=5, lw=1.5, label="Pareto front")
        ax.set_xlabel(_label(objectives[0]))
        ax.set_ylabel(_label(objectives[1]))
    else:
        low, high = values.min(axis=0), values.max(axis=0)
        scaled = (values - low) / np.where(high > low, high - low, 1.0)
        axes = np.arange(len(objectives))
        for mask, colour, width, label in (
            (~feasible, INFEASIBLE, 0.6, "infeasible"),
            (feasible & ~front, FEASIBLE, 0.6, "feasible"),
            (front, FRONT, 1.6, "Pareto front"),
        ):
            lines = scaled[mask]
            for i, line in enumerate(lines):
                ax.plot(axes, line, c=colour, lw=width, alpha=0.7, label=label if i == 0 else None)
        ax.set_xticks(axes, [_label(o) for o in objectives], rotation=15)
        ax.set_ylabel("scaled to the trials' range")
    ax.set_title(title)
    if len(ok):
        ax.legend(loc="best", fontsize="small")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    fig.savefig(tmp, format="png")
    tmp.replace(path)
    return path
