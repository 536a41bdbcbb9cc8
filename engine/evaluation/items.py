"""Evaluating the graph language beyond single nodes: repeated nodes and subgraph nodes.

A repeated node's items each have their own cache key, ``key({"node": base, "item":
token})``, where ``base`` hashes the node's inputs as written (an input that reads the loop
name enters as its text and the params it reads) and ``token`` is the item itself (a count's
index, a literal list's value) or, for an item from a wire, the wire's identity and the
index, never the data. So one more item computes one more item, and the node's own key (the
list of its items' keys) is what its users' keys see.

A subgraph node runs its file's graph (sharing the caches) with the node's inputs as params;
a wired input enters the subgraph's keys as the wire's identity.

:class:`LanguageRun` is a mixin of the evaluation run (:mod:`formgraph.evaluation.run`).
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..core.errors import BudgetError, ExpressionError, GraphError, NodeError, Problem
from ..core.registry import NodeSpec, _count
from ..core.types import loop_item_problem
from ..geometry import Points
from ..language.model import Expr, Input, Items, Literal, NodeDef, Wire, wires_of
from ..language.subgraph import SubgraphSpec
from . import cache as _cache
from .stats import NodeStat

# What one item of a repeated node costs against the element budget. An item is a whole
# node run (some 0.2 ms of bookkeeping even for a tiny node), so a count the budget would
# allow as elements (50 million) would run for hours: the default budget allows 50,000
# items, about ten seconds of the cheapest node.
ITEM_ELEMENTS = 1000
PROBES = 8  # items of a repeat asked what they would make before any runs

__all__ = [
    "ITEM_ELEMENTS",
    "LanguageRun",
    "file_stamp",
    "input_names",
    "reads_loop",
]


def input_names(value: Input, pt: Any) -> set[str]:
    """The names an input's expressions read (an expression port's text too)."""
    if isinstance(value, Expr):
        return set(value.compiled.names)
    if isinstance(value, Items):
        return {n for i in value.items for n in input_names(i, pt)}
    if (
        isinstance(value, Literal)
        and pt is not None
        and pt.is_expression
        and isinstance(value.value, str)
    ):
        from ..language.expr import compile_expression

        try:
            return set(compile_expression(value.value).names)
        except ExpressionError:
            return set()
    return set()


def reads_loop(value: Input, loop: str, pt: Any) -> bool:
    """Whether an input reads the loop name (and so differs item by item)."""
    return loop in input_names(value, pt)


def file_stamp(path: Any) -> tuple[int, int] | None:
    """(size, mtime in ns) of a written file, or None when it is gone."""
    try:
        st = os.stat(path)
    except (OSError, TypeError, ValueError):
        return None
    return st.st_size, st.st_mtime_ns


def _check_count(loop: str, where: Any, count: int, budget: int, scale: int = 1) -> None:
    """Refuse a repeat whose items would cost more than the element budget.

    ``scale`` is how many times the enclosing repeats run this graph (a repeated subgraph
    node that holds this repeat runs it once per outer item): the items cost the product.
    """
    total = count * scale
    if total * ITEM_ELEMENTS > budget:
        runs = (
            f"{count:,} items for each of the {scale:,} items of the repeats around it "
            f"({total:,} in all)"
            if scale > 1
            else f"{count:,} items"
        )
        raise BudgetError(
            [
                Problem(
                    where,
                    f"repeat '{loop}' would run {runs}, over the budget of "
                    f"{budget:,} elements: each item is a node run and counts as "
                    f"{ITEM_ELEMENTS:,} elements, so {_count(total * ITEM_ELEMENTS)} in all, "
                    f"and at most {budget // ITEM_ELEMENTS:,} items fit; raise it with "
                    "budget= or --budget if you mean it, or place copies with "
                    "mesh.copy_to_points",
                )
            ]
        )


class LanguageRun:
    """Repeated and subgraph nodes, for the evaluation run (``self`` is a ``_Run``)."""

    g: Any
    values: dict[str, Any]
    tokens: dict[str, Any]
    keys: dict[str, str]
    item_keys: dict[str, list[str]]
    items: dict[str, tuple[list[Any], list[Any]]]
    item_values: dict[str, dict[int, Any]]
    inner: dict[str, Any]
    stats: dict[str, Any]
    #: how many times the repeats around this run run it (1 at the top; a repeated
    #: subgraph node's run of its file has the product of the enclosing counts)
    scale: int = 1
    registry: dict[str, Any]

    def repeat_items(self, name: str) -> tuple[list[Any], list[Any]]:
        """The items of a repeated node and their key tokens (memoized; budget checked)."""
        if name in self.items:
            return self.items[name]
        r = self.g._nodes[name].repeat
        assert r is not None
        src = r.source
        where = self.where(name, "repeat")
        for w in wires_of(src):  # the count is known only from the value
            self.precheck_source(name, r.name, w.node, where)
            self.fetch(w.node)
        if isinstance(src, Wire):
            value = self.resolve(name, "repeat", src)
            token: Any = {"wire": self.identity(src.node), "output": src.output}
        else:
            value = self.resolve(name, "repeat", src)
            token = None if isinstance(src, (Literal, Expr)) else self.key_part_items(name, src)
        if isinstance(value, Points):
            # before a list of lists
            _check_count(r.name, where, len(value), self.g.budget, self.scale)
            value = value.xyz.tolist()
        elif isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, int) and not isinstance(value, bool):
            if value < 0:
                raise GraphError([Problem(where, f"a repeat count must be >= 0, got {value}")])
            count = value
        elif isinstance(value, (list, tuple)):
            _check_count(r.name, where, len(value), self.g.budget, self.scale)
            problem = loop_item_problem(value)
            if problem:
                raise GraphError([Problem(where, f"repeat '{r.name}': {problem}")])
            count = len(value)
        else:
            raise GraphError(
                [
                    Problem(
                        where,
                        f"repeat '{r.name}' runs over a count, a list or Points, got "
                        f"{type(value).__name__}",
                    )
                ]
            )
        _check_count(r.name, where, count, self.g.budget, self.scale)
        values = list(range(count)) if isinstance(value, int) else list(value)
        if token is None:
            tokens = values
        else:
            tokens = [{"source": token, "index": k} for k in range(count)]
        self.items[name] = (values, tokens)
        return self.items[name]

    def precheck_nested(self, name: str) -> None:
        """Budget a repeated subgraph node's inner repeats before anything runs.

        Each inner repeat whose count is known without running (no wire; its expression
        reads only params the node gives as literals or leaves at their defaults) is
        checked at the outer count times its own. Others are checked as each item's run of
        the file starts (see :attr:`scale`).
        """
        nd = self.g._nodes[name]
        spec = self.registry[nd.type]
        if nd.repeat is None or not isinstance(spec, SubgraphSpec):
            return
        count = len(self.repeat_items(name)[0])
        child = self.g._child(spec)
        given = {p: v for p, v in nd.inputs.items() if p in child._params}
        values = dict(child._values)
        values.update({p: v.value for p, v in given.items() if isinstance(v, Literal)})
        unknown = {p for p, v in given.items() if not isinstance(v, Literal)}
        probe = type(self)(child, values, {})
        probe.scale = self.scale * count
        for inner, ind in child._nodes.items():
            r = ind.repeat
            if r is None or wires_of(r.source) or input_names(r.source, None) & unknown:
                continue
            chain = f" (in the subgraph '{name}' of {self.g.file_label})"
            try:
                probe.repeat_items(inner)
                probe.precheck_nested(inner)
            except BudgetError as exc:
                problems = [Problem(p.where, p.message + chain) for p in exc.problems]
                raise BudgetError(problems) from None
            except GraphError:
                continue  # a bad count is reported, with its line, when the item runs

    def key_part_items(self, name: str, src: Input) -> Any:
        if isinstance(src, Wire):
            return {"wire": self.identity(src.node), "output": src.output}
        if isinstance(src, Items):
            return [self.key_part_items(name, i) for i in src.items]
        return _cache.canonical(self.resolve(name, "repeat", src))

    def lookup_items(self, name: str, spec: NodeSpec) -> tuple[bool, Any, str]:
        """A repeated node's value when every item is cached (the hits are remembered)."""
        found = self.item_values.setdefault(name, {})
        source = "memory"
        for k, key in enumerate(self.item_keys[name]):
            if k in found:
                continue
            hit, value, src = self.lookup(key, spec)
            if hit:
                found[k] = value
                source = src if src == "disk" else source
        if len(found) < len(self.item_keys[name]):
            return False, None, ""
        value = self.assemble(spec, [found[k] for k in range(len(found))])
        self.g._identity.setdefault(self.keys[name], self.keys[name])
        return True, value, source

    def assemble(self, spec: NodeSpec, values: list[Any]) -> Any:
        """The items' outputs as the node's list (items that are lists are joined)."""

        def join(column: list[Any], t: Any) -> list[Any]:
            listed = all(k.is_list for k in t.kinds)
            out: list[Any] = []
            for v in column:
                if isinstance(v, list) or (listed and isinstance(v, np.ndarray)):
                    out.extend(v)
                else:
                    out.append(v)
            return out

        if spec.multi_output:
            return spec.output_class(
                *(join([v[i] for v in values], t) for i, t in enumerate(spec.outputs.values()))
            )
        return join(values, spec.output_type(None))

    def compute_items(self, name: str, nd: NodeDef, spec: NodeSpec) -> Any:
        """Compute the items of a repeated node that no cache holds, each under its own key."""
        assert nd.repeat is not None
        loop = nd.repeat.name
        items, _ = self.repeat_items(name)
        found = self.item_values.setdefault(name, {})
        keys = self.item_keys[name]
        static = {
            port: v
            for port, v in nd.inputs.items()
            if not reads_loop(v, loop, spec.inputs[port].type)
        }
        base = self.inputs(name, nd, spec, None, skip=set(nd.inputs) - set(static))
        self.precheck_items(name, nd, spec, items, found, base, static)
        seconds = 0.0
        size = 0
        warnings: list[str] = []
        computed = 0
        for k, item in enumerate(items):
            if k in found:
                continue
            env = dict(self.values)
            env[loop] = item
            kwargs = dict(base)
            kwargs.update(self.inputs(name, nd, spec, env, only=set(nd.inputs) - set(static)))
            value, dt, w = self.call(name, nd, spec, kwargs, env)
            value = self.check_output(name, nd, spec, value)
            seconds += dt
            warnings.extend(f"item {k}: {m}" for m in w)
            n = _cache.sizeof(value)
            size += n
            self.g.memory.put(keys[k], value, n)
            if self.g.disk is not None:
                self.g.disk.put(keys[k], value, keys[k])
            self.g._identity[keys[k]] = keys[k]
            if spec.is_export:
                self.g._written[keys[k]] = file_stamp(value)
            found[k] = value
            computed += 1
        key = self.keys[name]
        self.g._identity[key] = key
        self.g._last[name] = (key, key)
        self.stats[name] = NodeStat(
            "computed", seconds, size, warnings, items=len(items), computed_items=computed
        )
        return self.assemble(spec, [found[k] for k in range(len(items))])

    def precheck_source(self, name: str, loop: str, source: str, where: Any) -> None:
        """Refuse a repeat over a wire whose source would make too many items, before the
        source is computed: asked what it would make (up to its budget check), one item
        per element it makes (a point of Points, an item of a list)."""
        if source in self.results:
            return
        nd = self.g._nodes[source]
        spec = self.registry.get(nd.type)
        if spec is None or nd.repeat is not None or nd.simulate is not None:
            return
        if any(u not in self.results for u in nd.upstream()):
            return  # its inputs are not known yet: the count check after it holds
        est = self.estimate(source, spec, self.inputs(source, nd, spec, None))
        if est is None or est * ITEM_ELEMENTS * self.scale <= self.g.budget:
            return
        raise BudgetError(
            [
                Problem(
                    where,
                    f"repeat '{loop}' would run about {_count(est)} items, one per element "
                    f"'{source}' makes: each item is a node run and counts as "
                    f"{ITEM_ELEMENTS:,} elements, so {_count(est * ITEM_ELEMENTS * self.scale)}"
                    f" in all, over the budget of {self.g.budget:,}, and at most "
                    f"{self.g.budget // ITEM_ELEMENTS:,} items fit (refused before '{source}' "
                    "runs)",
                )
            ]
        )

    def precheck_items(
        self,
        name: str,
        nd: NodeDef,
        spec: NodeSpec,
        items: list[Any],
        found: dict[int, Any],
        base: dict[str, Any],
        static: dict[str, Any],
    ) -> None:
        """Refuse a repeat whose items together would make more than the budget, before any
        runs: a few items (evenly spread) are asked what they would make (run up to their
        budget check only), and their mean times the items still to compute is the total."""
        assert nd.repeat is not None
        pending = [k for k in range(len(items)) if k not in found]
        if len(pending) < 2:
            return  # one item is checked by its own guard
        sample = sorted({pending[int(i)] for i in np.linspace(0, len(pending) - 1, PROBES)})
        sizes = []
        for k in sample:
            env = dict(self.values)
            env[nd.repeat.name] = items[k]
            kwargs = dict(base)
            kwargs.update(self.inputs(name, nd, spec, env, only=set(nd.inputs) - set(static)))
            est = self.estimate(name, spec, kwargs)
            if est is None:
                return  # it makes no budget check: each item's own run is all we know
            sizes.append(est)
        per = float(np.mean(sizes))
        total = per * len(pending)
        if total > self.g.budget:
            raise BudgetError(
                [
                    Problem(
                        self.where(name, "repeat"),
                        f"repeat '{nd.repeat.name}' would run {len(pending):,} items of about "
                        f"{_count(per)} elements each, {_count(total)} in all, over the budget "
                        f"of {self.g.budget:,} (raise it with budget= or --budget if you mean it)",
                    )
                ]
            )

    def run_subgraph(
        self,
        name: str,
        nd: NodeDef,
        spec: SubgraphSpec,
        kwargs: dict[str, Any],
        env: dict[str, Any] | None,
    ) -> Any:
        """Evaluate a subgraph's outputs with the node's inputs as its params.

        A wired input enters the subgraph's keys as the wire's identity, never hashed.
        """
        child = self.g._child(spec)
        values = dict(child._values)
        values.update(kwargs)
        tokens = {
            port: self.key_part(name, port, spec, v)
            for port, v in nd.inputs.items()
            if wires_of(v)
            and not (
                nd.repeat is not None and reads_loop(v, nd.repeat.name, spec.inputs[port].type)
            )
        }
        run = type(self)(child, values, tokens)
        # a repeated subgraph node runs its file once per item: its own repeats cost the
        # product, budgeted when the child's counts are known, before its items run
        run.scale = self.scale * (len(self.items[name][0]) if nd.repeat is not None else 1)
        targets = list(dict.fromkeys(w.node for w in spec.output_wires.values()))
        chain = f" (in the subgraph '{name}' of {self.g.file_label})"
        try:
            run.run(targets)
        except NodeError as exc:
            message = str(exc)[len(f"{exc.where.prefix()} ({exc.node_type}): ") :]
            raise NodeError(exc.where, exc.node_type, message + chain) from exc.__cause__
        except GraphError as exc:
            raise type(exc)([Problem(p.where, p.message + chain) for p in exc.problems]) from None
        self.inner[name] = run.stats
        outs = []
        for wire in spec.output_wires.values():
            outs.append(run.resolve(targets[0], "outputs", wire))
        return spec.output_class(*outs) if spec.multi_output else outs[0]
