"""Design-space sweeps: many variants of one graph, measured, exported and drawn.

>>> import formgraph as fg
>>> g = fg.load("graphs/spiral_tube.yaml")                          # doctest: +SKIP
>>> s = fg.sweep(g, vary={"turns": range(1, 13), "radius": [1, 2]})  # doctest: +SKIP
>>> s.rows[0]["status"], len(s.rows)                                 # doctest: +SKIP
('ok', 24)

A variant is one set of param values: a grid of every combination, or seeded random or
Latin hypercube samples (:mod:`formgraph.sweeps.sampling`), all checked before anything runs.

Every variant runs on Dask as part of one graph whose tasks are the nodes' cache keys
(:mod:`formgraph.sweeps.cluster`), so work that variants share is done once. With ``out``, the
table ``sweep.csv`` grows as variants finish; running the same sweep again keeps the rows
already done and runs the rest.
"""

from __future__ import annotations

import csv
import io
import json
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core.errors import ParamError, Problem, Where
from ..core.terminal import StatusLine
from ..evaluation.graph import Graph
from ..language.params import suggest
from .cluster import SweepError, Targets, Totals
from .sampling import Domain, domain, parse_spec, sample

__all__ = [
    "EACH_WORKER",
    "Domain",
    "Sweep",
    "SweepError",
    "domain",
    "parse_spec",
    "sample",
    "sweep",
    "TerminalProgress",
]

FIXED_COLUMNS = ("variant", "status", "error", "seconds")


# ----------------------------------------------------------------------- targets


def _targets(
    g: Graph, measure: Sequence[str], export: bool, render: str | None
) -> tuple[Targets, dict[str, type]]:
    """Measured columns (and their kinds), export nodes and the render node, all checked."""
    registry = g.node_types()  # the registry and the graph files it names
    problems: list[Problem] = []
    here = Where(g.file_label)
    measures: list[tuple[str, str | None, str]] = []
    kinds: dict[str, type] = {}

    def scalar(pt: Any) -> type | None:
        k = pt.kinds[0]
        ok = len(pt.kinds) == 1 and not k.is_list and k.base in (bool, int, float, str)
        return k.base if ok else None

    for item in measure:
        node, _, output = item.partition(".")
        if node not in g.nodes:
            problems.append(Problem(here, f"measure: no node '{node}'{suggest(node, g.nodes)}"))
            continue
        spec = registry[g.nodes[node]]
        if spec.is_export:
            problems.append(
                Problem(here, f"measure: '{node}' is an export; export its files with --export")
            )
            continue
        outs = spec.outputs if spec.multi_output else {None: spec.output_type(None)}
        if output and output not in outs:
            listed = ", ".join(f"{node}.{o}" for o in outs if o) or node
            problems.append(Problem(here, f"measure: '{item}': no such output; use {listed}"))
            continue
        chosen = [output] if output else list(outs)
        found = [(o, scalar(outs[o])) for o in chosen if scalar(outs[o]) is not None]
        if not found:
            what = outs[chosen[0]].name if len(chosen) == 1 else "none of its outputs"
            problems.append(
                Problem(
                    here,
                    f"measure: '{item}' gives {what}, not a number, bool or text; measure a "
                    f"node with scalar outputs (mesh.measure, curves.measure)",
                )
            )
        for o, kind in found:
            column = f"{node}.{o}" if o else node
            if column not in kinds:
                measures.append((node, o, column))
                kinds[column] = kind
    exports: tuple[str, ...] = ()
    if export:
        exports = tuple(n for n, t in g.nodes.items() if registry[t].is_export)
        if not exports:
            problems.append(Problem(here, "export: the graph has no export nodes"))
    if render is not None:
        if render not in g.nodes:
            problems.append(Problem(here, f"render: no node '{render}'{suggest(render, g.nodes)}"))
        elif not registry[g.nodes[render]].output_type(None).is_geometry:
            out = registry[g.nodes[render]].output_type(None).name
            problems.append(Problem(here, f"render: '{render}' gives {out}, nothing to draw"))
    clashes = [c for c in [*g.params, *kinds, *exports] if c in FIXED_COLUMNS]
    for c in clashes:
        problems.append(Problem(here, f"'{c}' would clash with the sweep.csv column '{c}'"))
    if problems:
        raise ParamError(problems)
    build: tuple[str, ...] = ()
    if not (measures or exports or render):  # still build each variant: what exports write
        sinks = g.sinks()
        names = [n for n in sinks if not registry[g.nodes[n]].is_export]
        for n in sinks:
            if registry[g.nodes[n]].is_export:
                names += list(g.plan(n)[-1].upstream)
        build = tuple(dict.fromkeys(names))
    return Targets(tuple(measures), exports, render, build=build), kinds


# ------------------------------------------------------------------------ result


@dataclass
class Sweep:
    """A finished sweep: one row per variant, and what it cost.

    ``rows`` are dicts: ``variant``, every param, ``status`` ('ok' or 'failed'), ``error``,
    ``seconds``, each measured column and each export's path (relative to the output folder).
    """

    rows: list[dict[str, Any]]
    columns: list[str]
    totals: Totals = field(default_factory=Totals)
    seconds: float = 0.0
    resumed: int = 0  # rows kept from an earlier run of the same sweep
    sheets: list[Path] = field(default_factory=list)
    csv_path: Path | None = None

    @property
    def failed(self) -> int:
        return sum(1 for r in self.rows if r["status"] == "failed")

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write the table (atomically); returns the path."""
        path = Path(path)
        _write_atomic(path, _table_text(self.columns, self.rows))
        return path

    def summary(self) -> str:
        t = self.totals
        lines = [
            f"{len(self.rows)} variants: {len(self.rows) - self.failed} ok, {self.failed} "
            f"failed, in {self.seconds:.1f} s"
            + (f" ({self.resumed} kept from an earlier run)" if self.resumed else "")
        ]
        if t.variants:
            saved = 1 - t.needed / t.naive if t.naive else 0.0
            lines.append(
                f"node evaluations: {t.needed:,} needed for {t.variants:,} variants x their "
                f"nodes = {t.naive:,} ({saved:.0%} shared); {t.computed:,} computed, "
                f"{t.cached:,} from the disk cache"
            )
        if self.csv_path is not None:
            lines.append(f"wrote {self.csv_path}")
        lines += [f"wrote {p}" for p in self.sheets]
        return "\n".join(lines)


_FORMULA = ("=", "+", "-", "@", "\t", "\r")  # what a spreadsheet reads as a formula's start


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _inert(text: str) -> str:
    """A text cell a spreadsheet shows as text: one leading ``'`` before ``= + - @`` (and
    before a ``'`` already leading such a cell, so :func:`_active` undoes exactly this);
    numbers (``-1.5``) are left as they are."""
    if text.lstrip("'").startswith(_FORMULA) and not _is_number(text):
        return "'" + text
    return text


def _active(text: str) -> str:
    """The text :func:`_inert` was given."""
    if text.startswith("'") and text.lstrip("'").startswith(_FORMULA):
        return text[1:]
    return text


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return _inert(v)  # params, file names and errors: never a formula (CSV injection)
    return _inert(json.dumps(v))


def _parse_cell(text: str, kind: type | None) -> Any:
    text = _active(text)
    if kind is None or text == "":
        return text if kind is str or kind is None else None
    if kind is bool:
        return text == "true"
    try:
        return kind(text)
    except ValueError:
        return text


def _line(values: Sequence[str]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(values)
    return buf.getvalue()


def _table_text(columns: Sequence[str], rows: Iterable[Mapping[str, Any]]) -> str:
    return _line([_inert(c) for c in columns]) + "".join(
        _line([_cell(r.get(c)) for c in columns]) for r in rows
    )


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


class _Table:
    """``sweep.csv`` as rows finish: each row one ``write`` to a file opened for appending,
    so an interrupted sweep leaves a table whose every line is a whole row."""

    def __init__(self, path: Path, columns: list[str]):
        self.path = path
        self.columns = columns
        self.fd: int | None = None

    def previous(self) -> dict[int, dict[str, str]]:
        """The rows an earlier run of the same sweep left (same columns), by variant."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return {}
        text = text[: text.rfind("\n") + 1]  # a line cut short by a crash is dropped
        reader = csv.reader(io.StringIO(text))
        if next(reader, None) != [_inert(c) for c in self.columns]:
            return {}
        out: dict[int, dict[str, str]] = {}
        for cells in reader:
            if len(cells) == len(self.columns) and cells[0].isdigit():
                out.setdefault(int(cells[0]), dict(zip(self.columns, cells, strict=True)))
        return out

    def start(self, rows: Iterable[Mapping[str, Any]]) -> None:
        _write_atomic(self.path, _table_text(self.columns, rows))
        self.fd = os.open(self.path, os.O_WRONLY | os.O_APPEND)

    def append(self, row: Mapping[str, Any]) -> None:
        assert self.fd is not None
        os.write(self.fd, _line([_cell(row.get(c)) for c in self.columns]).encode())

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


class TerminalProgress(StatusLine):
    """'sweep 37/200 done, 2 failed, 4.1/s, ETA 0:40' on a terminal, at most 10 times a second."""

    def __init__(self, stream: Any = None):
        super().__init__(stream if stream is not None else sys.stderr, interval=0.1)

    def __call__(self, done: int, total: int, failed: int, rate: float) -> None:
        self.show(progress_text(done, total, failed, rate), force=done >= total)


def progress_text(done: int, total: int, failed: int, rate: float) -> str:
    """The progress line: done / total, failed, variants per second, time left."""
    text = f"sweep {done}/{total} done, {failed} failed"
    if rate > 0:
        left = (total - done) / rate
        text += f", {rate:.1f}/s, ETA {int(left // 60)}:{int(left % 60):02d}"
    return text


class _EachWorker:
    def __repr__(self) -> str:
        return "EACH_WORKER"


EACH_WORKER: Any = _EachWorker()  # cache_dir: each worker's own default cache folder
_GRAPH_CACHE: Any = object()


def sweep(
    graph: Graph | str | os.PathLike[str],
    vary: Mapping[str, Any],
    measure: Sequence[str] = (),
    *,
    method: str = "grid",
    samples: int | None = None,
    seed: int = 0,
    export: bool = False,
    render: str | None = None,
    out: str | os.PathLike[str] | None = None,
    client: Any = None,
    workers: int | None = None,
    cache_dir: Any = _GRAPH_CACHE,
    shared_cache: bool = False,
    size: tuple[int, int] = (256, 192),
    camera: tuple[Any, Any, Any] | None = None,
    per_sheet: int = 100,
    on_row: Callable[[dict[str, Any]], None] | None = None,
    progress: Callable[[int, int, int, float], None] | None = None,
) -> Sweep:
    """Run variants of ``graph`` on Dask and tabulate them.

    Parameters
    ----------
    graph : Graph or path
        The graph; its current param values are the fixed ones.
    vary : mapping
        Param name -> values: SPEC text (``"1:12"``, ``"0.5:2:7"``, ``"1,2,5"``, ``"0.5:2"``
        an interval for random and lhs), or a range, list or single value. Checked against
        each param's type, min, max and choices before anything runs.
    measure : list of str
        ``node`` or ``node.output`` with scalar outputs (a node with several outputs gives
        a ``node.output`` column for each scalar one).
    method : {'grid', 'random', 'lhs'}
        Every combination, or ``samples`` random or Latin hypercube variants (``seed``).
    export : bool
        Run every export node; each variant's files go to ``out/variants/NNNN/``.
    render : str, optional
        A node drawn for each variant, tiled into ``out/sheet.png`` (``per_sheet`` cells of
        ``size`` pixels each, then ``sheet-2.png``, ...).
    camera : (view, azimuth, elevation), optional
        Where the cells look from, as ``formgraph.viewer.Camera`` takes them
        (``("top", None, None)``, ``(None, 30, 20)``); default: each cell fits its value.
    out : path, optional
        Where ``sweep.csv`` grows as variants finish; rerunning the same sweep there keeps
        the rows already done (needed for export and render).
    client : distributed.Client or str, optional
        A Dask client, or a scheduler address (``tcp://host:8786``); default: an embedded
        LocalCluster of ``workers`` single-threaded processes (one per core), closed after.
    cache_dir : path, None or EACH_WORKER
        The disk cache workers use; default the graph's own (``cache_dir=`` of load).
    shared_cache : bool
        ``cache_dir`` is one folder that the client and every worker see (a shared
        filesystem): nodes found there are loaded, not scheduled, on a remote cluster too.
    on_row, progress : callables, optional
        Called on the client with each finished row dict, and with
        (done, total, failed, variants per second).

    Raises
    ------
    ParamError
        For bad varied params, measures, exports or render node (all problems at once).
    ValueError
        For a bad method or sample count.
    SweepError
        When the cluster cannot be reached or the graph cannot be sent to it.
    """
    from ..core import safety
    from ..evaluation.graph import load
    from . import cluster as run_dask

    g = load(graph) if isinstance(graph, (str, os.PathLike)) else graph
    problems: list[Problem] = []
    domains = []
    for name, spec in vary.items():
        try:
            domains.append(domain(g, name, spec))
        except ParamError as exc:
            problems += exc.problems
    try:
        targets, kinds = _targets(g, list(measure), export, render)
    except ParamError as exc:
        problems += exc.problems
    if problems:
        raise ParamError(problems)
    if not domains:
        raise ValueError("vary at least one param")
    if (export or render) and out is None:
        raise ValueError("export and render write files: give out=")
    if camera is not None:
        from formgraph.viewer.frame import Camera

        camera = tuple(camera)
        Camera(*camera)  # a ValueError for a bad view or angle, before anything runs
    targets = Targets(targets.measures, targets.exports, render, size, targets.build, camera)
    variants = sample(domains, method, samples, seed)
    base = g.params
    columns = ["variant"]
    columns += [n for n, v in base.items() if n in vary or _tabular(v)]
    columns += ["status", "error", "seconds", *kinds, *targets.exports]
    width = max(4, len(str(len(variants) - 1)))
    out_dir = None if out is None else Path(out)
    table = None if out_dir is None else _Table(out_dir / "sweep.csv", columns)
    rows: dict[int, dict[str, Any]] = {}
    params_of = [{**base, **v} for v in variants]

    def files_of(i: int) -> list[str]:
        folder = f"variants/{i:0{width}d}"
        return [f"{folder}/{render}.png"] if render else []

    if isinstance(client, str):
        # before sweep.csv is touched: an unreachable scheduler leaves no file behind
        run_dask.probe_scheduler(client)
    if table is not None:
        for i, cells in table.previous().items():
            row = _kept(cells, i, params_of, columns, kinds, targets.exports)
            needs = files_of(i) + [row[e] for e in targets.exports] if row else []
            if row is not None and all((out_dir / f).is_file() for f in needs):
                rows[i] = row
        table.start(rows[i] for i in sorted(rows))
    resumed = len(rows)
    t0 = time.perf_counter()
    failed = sum(1 for r in rows.values() if r["status"] == "failed")

    def finished(i: int, result: run_dask.RowResult) -> None:
        nonlocal failed
        folder = f"variants/{i:0{width}d}"
        row: dict[str, Any] = {"variant": i}
        row.update({c: params_of[i][c] for c in columns if c in params_of[i]})
        row.update(status="ok" if result.error is None else "failed", error=result.error or "")
        row["seconds"] = round(result.seconds, 6)
        row.update({c: result.values.get(c) for c in kinds})
        for name, (main, files) in result.exports.items():
            for rel, data in files.items():
                safety.write_atomic(out_dir, f"{folder}/{rel}", data)
            row[name] = f"{folder}/{main}"
        if result.image is not None:
            safety.write_atomic(out_dir, files_of(i)[0], result.image)
        rows[i] = row
        failed += row["status"] == "failed"
        if table is not None:
            table.append(row)
        if progress is not None:
            rate = (len(rows) - resumed) / max(time.perf_counter() - t0, 1e-9)
            progress(len(rows), len(variants), failed, rate)
        if on_row is not None:
            on_row(row)

    if cache_dir is _GRAPH_CACHE:
        cache_dir = g.disk.root if g.disk is not None else None
    todo = [(i, v) for i, v in enumerate(variants) if i not in rows]
    try:
        totals = run_dask.run(
            g,
            todo,
            targets,
            finished,
            client=client,
            workers=workers,
            cache_dir=None if cache_dir is EACH_WORKER else cache_dir,
            worker_cache=cache_dir is EACH_WORKER,
            shared_disk=shared_cache and cache_dir is not EACH_WORKER,
        )
    finally:
        if table is not None:
            table.close()
    result = Sweep([rows[i] for i in sorted(rows)], columns, totals, resumed=resumed)
    if table is not None:
        result.csv_path = result.to_csv(table.path)  # finished: in variant order
    if render is not None and out_dir is not None:
        from formgraph.viewer.sheet import contact_sheet

        cells = []
        for r in result.rows:
            image = out_dir / files_of(r["variant"])[0]
            cells.append((_label(r, vary), image if image.is_file() else None))
        result.sheets = contact_sheet(cells, out_dir / "sheet.png", size=size, per_sheet=per_sheet)
    result.seconds = time.perf_counter() - t0
    return result


def _tabular(value: Any) -> bool:
    if isinstance(value, (bool, int, float, str)) or value is None:
        return True
    return isinstance(value, list) and all(isinstance(v, (int, float, str)) for v in value)


def _label(row: Mapping[str, Any], vary: Iterable[str]) -> str:
    def short(v: Any) -> str:
        return f"{v:.4g}" if isinstance(v, float) else _cell(v)

    return f"#{row['variant']} " + " ".join(f"{n}={short(row[n])}" for n in vary)


def _kept(
    cells: Mapping[str, str],
    i: int,
    params_of: Sequence[Mapping[str, Any]],
    columns: Sequence[str],
    kinds: Mapping[str, type],
    exports: Sequence[str],
) -> dict[str, Any] | None:
    """A row of an earlier run as this run would write it, or None when it must run again
    (another variant under that number, a failure, a row of a sweep with other variants)."""
    if i >= len(params_of) or cells.get("status") != "ok":
        return None
    params = params_of[i]
    if any(cells[c] != _cell(params[c]) for c in columns if c in params):
        return None
    row: dict[str, Any] = {"variant": i}
    row.update({c: params[c] for c in columns if c in params})
    row.update(status="ok", error="", seconds=_parse_cell(cells["seconds"], float))
    row.update({c: _parse_cell(cells[c], k) for c, k in kinds.items()})
    row.update({e: _active(cells[e]) for e in exports})
    return row
