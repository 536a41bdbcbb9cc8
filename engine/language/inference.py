"""What the check reads into a graph before it checks it (``g`` is the check's
:class:`~.check.Outline`): each param's type from the ports it feeds, and expression ports
written with the ``=`` of a param expression."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..core.registry import NodeSpec
from .model import Expr, Literal, NodeDef

__all__ = ["expression_ports_take_text", "infer_fed"]


def expression_ports_take_text(g: Any, nd: NodeDef, spec: NodeSpec) -> None:
    """Read ``z: "=wall/2"`` on an expression port as the expression ``wall/2``.

    An expression port takes the text of an expression; written with the ``=`` of a
    param expression it is still one expression (over the port's variables and the
    params), so the ``=`` is dropped rather than the text evaluated once with the param
    defaults. ``"=shape"`` naming a text param still passes that param's text.
    """
    for port, value in nd.inputs.items():
        if not isinstance(value, Expr) or port not in spec.inputs:
            continue
        if not spec.inputs[port].type.is_expression:
            continue
        if value.compiled.is_bare_name:
            p = g.params.get(value.text.strip())
            if p is not None and (isinstance(p.default, str) or p.type is not None):
                continue
        nd.inputs[port] = Literal(value.text)


def infer_fed(g: Any, registry: Mapping[str, NodeSpec]) -> None:
    """Set each param's ``fed``: float when the expressions that read it feed float ports
    only (``radius: "=r"``), None when any feeds an int port (``count: "=r"``) or none does.
    """
    votes: dict[str, set[type]] = {name: set() for name in g.params}
    for nd in g.nodes.values():
        spec = registry.get(nd.type)
        if spec is None:
            continue
        for port, value in nd.inputs.items():
            if not isinstance(value, Expr) or port not in spec.inputs:
                continue
            bases = {k.base for k in spec.inputs[port].type.kinds if not k.is_list}
            kind = float if float in bases and int not in bases else int if int in bases else None
            if kind is None:
                continue
            for name in value.compiled.names & votes.keys():
                votes[name].add(kind)
    for name, p in g.params.items():
        p.fed = float if votes[name] == {float} else None
