"""Keys kept per graph version: a fully cached re-evaluation reuses the last run's order
and keys (the part of :class:`~formgraph.evaluation.run._Run` that remembers them)."""

from __future__ import annotations

from typing import Any

from . import cache as _cache

__all__ = ["Replay"]


class Replay:
    """Mixed into ``_Run`` (which holds ``g``, ``values``, ``keys``, ``registry``, ...)."""

    g: Any
    values: dict[str, Any]
    keys: dict[str, str]
    registry: dict[str, Any]
    pure: bool
    tokens: dict[str, Any]
    out_dir: str

    # Keys kept per graph version: a run of the same targets with the same params on the
    # unchanged graph (every change clears `_replay`) whose upstream identities are all
    # still what they were has the same keys, so the order and the keys of the last such run
    # are reused instead of rebuilding every key's text (2 ms for 200 nodes; the check of
    # the identities is a dict look-up a node). Only plain runs: no plan (pure), no wired
    # subgraph params (tokens), no repeated or simulated nodes (their items and steps are
    # found with their keys), no input files (their bytes are in the keys).
    _REPLAYS = 8  # target lists remembered per graph

    def _replay_state(self, order: list[str]) -> tuple | None:
        if self.pure or self.tokens:
            return None
        try:
            values = _cache.key_text(self.values)
        except (TypeError, ValueError):
            return None
        specs = tuple(self.registry.get(self.g._nodes[n].type) for n in order)
        # the output folder is in the keys of exports only (resolved only then)
        exports = any(getattr(spec, "is_export", False) for spec in specs)
        return values, self.out_dir if exports else None, specs

    def replay(self, targets: list[str]) -> list[str] | None:
        memo = self.g._replay.get(tuple(targets))
        if memo is None:
            return None
        order, state, keys, identities = memo
        if self._replay_state(order) != state:
            return None
        ident = self.g._identity
        for key, identity in identities.items():
            if ident.get(key) != identity:
                return None
        self.keys.update(keys)
        return order

    def remember(self, targets: list[str], order: list[str]) -> None:
        if getattr(self, "keyed_files", False):  # an input file may change between runs
            return
        nodes = self.g._nodes
        if any(nodes[n].repeat is not None or nodes[n].simulate is not None for n in order):
            return
        state = self._replay_state(order)
        if state is None:
            return
        keys = {n: self.keys[n] for n in order if n in self.keys}
        if len(keys) != len(order):
            return
        ident = self.g._identity
        identities = {k: ident[k] for k in keys.values() if k in ident}
        if len(identities) != len(set(keys.values())):
            return
        memo = self.g._replay
        if len(memo) >= self._REPLAYS:
            memo.pop(next(iter(memo)))
        memo[tuple(targets)] = (order, state, keys, identities)
