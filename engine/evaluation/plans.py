"""Plans for sweeps: every variant's nodes keyed before anything runs, and one planned node
computed from its inputs' outputs (the methods of :class:`formgraph.Graph` a sweep uses,
kept apart from the graph's building and evaluation)."""

from __future__ import annotations

import hashlib
import os
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..core.registry import node_types
from ..language.model import Literal, wires_of
from . import cache as _cache
from .items import input_names
from .run import NodeStat, Step, _Run

__all__ = ["Plans"]


class Plans:
    """Mixed into :class:`formgraph.Graph` (which holds the state these methods read)."""

    def plan(self, targets: str | Iterable[str], **params: Any) -> list[Step]:
        """The nodes that ``targets`` need, in evaluation order, each with its cache key.

        Keys are those of a cold evaluation with these params: they depend only on what goes
        into each node (no early cutoff, which needs earlier outputs), so a sweep can key
        every variant's nodes before anything runs and share the nodes whose keys agree.
        Nothing is evaluated (except the inputs a repeat count is read from).
        """
        if not self._checked:
            self.check()
        values = dict(self._values)
        values.update(self._checked_params(params))
        run = _Run(self, values, pure=True)
        names = [targets] if isinstance(targets, str) else list(targets)
        steps = []
        for n in self._order(names):
            up = tuple(dict.fromkeys(self._nodes[n].upstream()))
            export = run.registry[self._nodes[n].type].is_export
            steps.append(Step(n, run.key(n), up, export, tuple(run.keys[u] for u in up)))
        return steps

    def plans(
        self, targets: str | Iterable[str], variants: Iterable[dict[str, Any]]
    ) -> list[list[Step]]:
        """:meth:`plan` of each of many param sets (a sweep's variants): the same steps.

        Planned in bulk: the graph is checked, the order found and the run set up once; a
        node that reads no param any variant sets, and no node that does, is keyed once
        for all of them; a node that does has its key text laid out once with a slot for
        each port that varies, and each variant fills in only those ports' parts (its own
        expressions evaluated, its upstream keys) before the text is hashed. A graph with
        repeated or simulated nodes is planned variant by variant, as :meth:`plan` does.
        """
        if not self._checked:
            self.check()
        names = [targets] if isinstance(targets, str) else list(targets)
        order = self._order(names)
        ups = [tuple(dict.fromkeys(self._nodes[n].upstream())) for n in order]
        registry = {**node_types(), **self._subgraphs}
        exports = [registry[self._nodes[n].type].is_export for n in order]
        checked = [self._checked_params(params) for params in variants]
        looped = any(
            self._nodes[n].repeat is not None or self._nodes[n].simulate is not None for n in order
        )
        if looped or len(checked) < 2:
            keyed = [self._keyed_one(order, given) for given in checked]
        else:
            keyed = self._keyed_bulk(order, checked)
        return [
            [
                Step(n, keys[n], up, export, tuple(keys[u] for u in up))
                for n, up, export in zip(order, ups, exports, strict=True)
            ]
            for keys in keyed
        ]

    def _keyed_one(self, order: list[str], given: dict[str, Any]) -> dict[str, str]:
        values = dict(self._values)
        values.update(given)
        run = _Run(self, values, pure=True)
        for n in order:
            run.key(n)
        return run.keys

    def _keyed_bulk(self, order: list[str], checked: list[dict[str, Any]]) -> list[dict[str, str]]:
        """Each variant's keys of ``order`` (plain nodes only), as :meth:`_keyed_one` gives
        them (tests/test_plans.py holds the two equal over random graphs and variants)."""
        varied = set().union(*checked)
        run = _Run(self, dict(self._values), pure=True)
        fixed: dict[str, str] = {}  # node -> its key in every variant
        varying: list[tuple[str, Any, Any, list[str], list[str] | None]] = []
        moved: set[str] = set()
        nonce = os.urandom(8).hex()
        for n in order:
            nd = self._nodes[n]
            spec = run.registry[nd.type]
            ports = [
                port
                for port, value in nd.inputs.items()
                if _varies(value, spec.inputs[port].type, varied, moved)
            ]
            if not ports:
                fixed[n] = run.key(n)
                continue
            moved.add(n)
            pieces = None  # a file port: the whole key per variant (its file read once)
            if not any(port in spec.input_paths for port in ports):
                slots = {port: f"\0{nonce}:{i}\0" for i, port in enumerate(ports)}
                text = _cache.key_text(run.key_parts(n, nd, spec, slots))
                found = sorted((text.find(_cache.key_text(s)), p) for p, s in slots.items())
                if all(text.count(_cache.key_text(s)) == 1 for s in slots.values()):
                    ports = [p for _, p in found]
                    pieces, at = [], 0
                    for start, p in found:
                        pieces.append(text[at:start])
                        at = start + len(_cache.key_text(slots[p]))
                    pieces.append(text[at:])
            varying.append((n, nd, spec, ports, pieces))
        out = []
        base = self._values
        key_text, blake2b = _cache.key_text, hashlib.blake2b
        for given in checked:
            run.values = {**base, **given}
            run.keys = keys = dict(fixed)
            for n, nd, spec, ports, pieces in varying:
                if pieces is None:
                    run.key(n)
                    continue
                text = pieces[0]
                for port, piece in zip(ports, pieces[1:], strict=True):
                    text += key_text(run.port_part(n, port, spec, nd.inputs[port])) + piece
                keys[n] = blake2b(text.encode(), digest_size=20).hexdigest()
            out.append(keys)
        return out

    def compute_step(
        self,
        step: Step,
        inputs: dict[str, Any],
        *,
        out_dir: str | os.PathLike[str] | None = None,
        **params: Any,
    ) -> tuple[Any, NodeStat]:
        """Node ``step.name``'s output from its inputs' outputs, through the caches.

        ``step`` comes from :meth:`plan` with the same params; ``inputs`` maps each of
        ``step.upstream`` to its output. A value cached under ``step.key`` is returned as it
        is; a computed one is cached under it. Exports always run, writing into ``out_dir``
        (default :attr:`out_dir`).

        Raises
        ------
        NodeError, GraphError
            As :meth:`evaluate` does for the node.
        """
        # A variant's steps come one after another with the same params: checked once.
        memo = self._step_params
        try:
            text = _cache.key_text(params) if params else ""
        except (TypeError, ValueError):
            text = None
        if memo is not None and text is not None and memo[0] == text:
            values = dict(memo[1])
        else:
            values = dict(self._values)
            values.update(self._checked_params(params))
            self._step_params = (text, values)
            values = dict(values)
        run = _Run(self, values, pure=True)
        if out_dir is not None:
            run.out_path = Path(out_dir).resolve()
            run.out_dir = str(run.out_path)
        run.keys.update(zip(step.upstream, step.upstream_keys, strict=True))
        run.results.update(inputs)
        nd = self._nodes[step.name]
        spec = run.registry[nd.type]
        if nd.repeat is None and nd.simulate is None:
            run.keys[step.name] = step.key
        else:
            run.key(step.name)  # its items' keys (the count may come from an input)
        t0 = time.perf_counter()
        if not spec.is_export:
            if nd.repeat is not None:
                hit, value, source = run.lookup_items(step.name, spec)
            elif nd.simulate is not None:
                hit, value, source = run.lookup_steps(step.name, spec)
            else:
                hit, value, source = run.lookup(step.key, spec)
            if hit:
                return value, NodeStat("cached", time.perf_counter() - t0, source=source)
        if nd.repeat is not None:
            value = run.compute_items(step.name, nd, spec)
        elif nd.simulate is not None:
            value = run.compute_steps(step.name, nd, spec)
        else:
            value = run.compute(step.name, nd, spec)
        return value, run.stats[step.name]

    def cached(self, step: Step) -> tuple[bool, Any]:
        """(True, output) when a cache holds planned ``step``'s output, else (False, None).

        Exports (their file may be gone) and repeated nodes are never answered this way.
        """
        nd = self._nodes[step.name]
        run = _Run(self, dict(self._values), pure=True)
        spec = run.registry[nd.type]
        if spec.is_export or nd.repeat is not None or nd.simulate is not None:
            return False, None
        hit, value, _ = run.lookup(step.key, spec)
        return hit, value


def _varies(value: Any, pt: Any, varied: set[str], moved: set[str]) -> bool:
    """Whether an input's part of a key can differ between variants: it wires a node that
    varies, or reads a param that some variant sets (an expression port's text computed
    by an expression might read any: it always varies)."""
    if any(w.node in moved for w in wires_of(value)):
        return True
    if pt.is_expression and not isinstance(value, Literal):
        return True
    return bool(input_names(value, pt) & varied)
