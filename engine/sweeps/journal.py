"""An optimisation study's journal: ``study.journal``, one JSON line per told trial.

The first line is the study's question (params, objectives, constraints, method, seed,
batch); each further line is one finished trial as optuna holds it (number, state, params
and their distributions, values, user and system attributes: the constraints, NSGA-II's
generation, CMA-ES's state). A batch's lines are one ``write`` to a file opened for
appending, then one ``fsync``, so a crash leaves whole lines and at most a cut-short last
one, which is ignored. optuna's own journal storage writes and syncs a record for every
ask, suggestion, attribute and tell (seven per trial here, 9 ms each on a busy disk):
replaying told trials into an in-memory study gives the sampler the same history for a
fraction of that.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

__all__ = ["Journal", "replay", "tell_recorded"]

CONSTRAINTS = "constraints:"  # optuna's system attribute of a trial's constraint values


class Journal:
    """The journal file of a study in ``path``."""

    def __init__(self, path: Path):
        self.path = path

    def read(self) -> tuple[str | None, list[dict[str, Any]]]:
        """(question, trial records); (None, []) when there is no journal yet."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None, []
        lines = text[: text.rfind("\n") + 1].splitlines()  # a line cut short is dropped
        if not lines:
            return None, []
        try:
            head = json.loads(lines[0])
            question = head["question"] if isinstance(head, dict) else None
        except (ValueError, KeyError):
            question = None
        if not isinstance(question, str):
            raise ValueError(f"{self.path} is not a formgraph study journal")
        records = []
        for line in lines[1:]:
            try:
                rec = json.loads(line)
            except ValueError:
                continue
            if isinstance(rec, dict) and isinstance(rec.get("number"), int):
                records.append(rec)
        return question, records

    def start(self, question: str) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._append([json.dumps({"question": question})])

    def append(self, trials: Iterable[Any], batch: int) -> None:
        """Record optuna FrozenTrials (told) in one write; ``batch`` is the number of the
        first trial of their batch (a resumed study tells the last batch after asking the
        next, as the uninterrupted study did)."""
        from optuna.distributions import distribution_to_json

        lines = []
        for t in trials:
            rec = {
                "number": t.number,
                "state": t.state.name,
                "params": t.params,
                "distributions": {k: distribution_to_json(d) for k, d in t.distributions.items()},
                "values": t.values,
                "user_attrs": t.user_attrs,
                "system_attrs": t.system_attrs,
                "batch": batch,
            }
            lines.append(json.dumps(rec))
        if lines:
            self._append(lines)

    def _append(self, lines: list[str]) -> None:
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, ("\n".join(lines) + "\n").encode())
            os.fsync(fd)
        finally:
            os.close(fd)


def replay(
    optuna: Any, study: Any, records: list[dict[str, Any]], batch: int
) -> list[tuple[int, dict[str, Any]]]:
    """Add recorded trials to an in-memory ``study``: trials 0, 1, 2, ... as long as they
    run on (a number recorded twice counts once; nothing after a gap is trusted).

    The last batch is added as running trials (their params, none of what their tell set):
    the study asked its next batch before telling it, so the caller asks that batch first
    and then tells these, with :func:`tell_recorded`. Returns (trial id, record) for them.
    ``batch`` is the study's batch size, for a journal whose records do not say their batch.
    """
    from optuna.distributions import json_to_distribution

    by_number: dict[int, dict[str, Any]] = {}
    for rec in records:
        by_number.setdefault(rec["number"], rec)
    ordered = []
    while len(ordered) in by_number:
        ordered.append(by_number[len(ordered)])
    if not ordered:
        return []
    last = ordered[-1].get("batch")
    if not isinstance(last, int) or not 0 <= last < len(ordered):
        last = (len(ordered) - 1) // batch * batch
    held = []
    for rec in ordered:
        state = optuna.trial.TrialState[rec["state"]]
        running = rec["number"] >= last
        study.add_trial(
            optuna.trial.create_trial(
                state=optuna.trial.TrialState.RUNNING if running else state,
                params=rec["params"],
                distributions={k: json_to_distribution(d) for k, d in rec["distributions"].items()},
                values=rec["values"]
                if state == optuna.trial.TrialState.COMPLETE and not running
                else None,
                user_attrs={} if running else rec["user_attrs"],
                system_attrs={
                    k: v
                    for k, v in rec["system_attrs"].items()
                    if not (running and k.startswith(CONSTRAINTS))
                },
            )
        )
        if running:
            held.append((study.get_trials(deepcopy=False)[-1]._trial_id, rec))
    return held


def tell_recorded(optuna: Any, study: Any, trial_id: int, rec: dict[str, Any]) -> None:
    """Tell a trial :func:`replay` added as running what its record says."""
    trial = optuna.trial.Trial(study, trial_id)
    for k, v in rec["user_attrs"].items():
        trial.set_user_attr(k, v)
    for k, v in rec["system_attrs"].items():
        if k.startswith(CONSTRAINTS):  # set at the tell, as the study set them
            trial.set_constraint(k[len(CONSTRAINTS) :], v)
    state = optuna.trial.TrialState[rec["state"]]
    if state == optuna.trial.TrialState.COMPLETE:
        study.tell(trial, rec["values"])
    else:
        study.tell(trial, state=state)
