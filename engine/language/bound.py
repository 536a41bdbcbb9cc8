"""An expression with its graph params bound: what a node's expression input receives.

It is called with the node's own variables (``t``, ``u``, ``v``, ``x``, ...) and knows its
exact derivatives (:mod:`.derivative`), so curves and surfaces from expressions measure
their length and normals exactly.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .derivative import taylor
from .expr import Compiled, compile_expression  # noqa: F401  (compile_expression: the doctest)

__all__ = ["Bound"]


@dataclass(frozen=True)
class Bound:
    """An expression with its graph params bound; nodes call it with their own variables.

    Example
    -------
    >>> x = Bound(compile_expression("r * cos(t)"), {"r": 2.0})
    >>> float(x(t=0.0))
    2.0
    """

    compiled: Compiled
    params: Mapping[str, Any]

    @property
    def text(self) -> str:
        return self.compiled.text

    def __call__(self, **variables: Any) -> Any:
        return self.compiled(self.params, **variables)

    def taylor(self, variable: str, **variables: Any) -> tuple[Any, Any, Any]:
        """Value, first and second derivative in ``variable``, exact (see
        :mod:`~formgraph.language.derivative`; raises ``NotDifferentiable`` for noise)."""
        return taylor(self.compiled.text, variable, {**self.params, **variables})
