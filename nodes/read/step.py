"""``read.step``: the solids of a STEP file, exact (OpenCASCADE's reader, in a child process
budgeted by the file's entity count and bounded in time:
:mod:`formgraph.kernels.brep.stepread`)."""

from __future__ import annotations

import hashlib

from formgraph.core.errors import InputError
from formgraph.core.registry import Context, node
from formgraph.core.types import InputPath
from formgraph.geometry import Solid
from formgraph.nodes.brep._common import requires


@node("read.step", version=1, requires=requires)
def step(path: InputPath, *, ctx: Context) -> list[Solid]:
    """Read the solids of a STEP file (AP203, AP214, AP242), exact: faces on their planes,
    cylinders and B-splines, ready to fillet, cut and write again.

    A closed shell written without its solid is read as a solid; a file of open surfaces
    only is an error. The file's entities are counted against the run's budget before it is
    parsed, and the reading is stopped after two minutes.

    Parameters
    ----------
    path : InputPath
        The file, relative to the graph's folder (or the inputs folder), e.g. ``part.step``.

    Example
    -------
    ``part: {type: read.step, path: bracket.step}``
    """
    from formgraph.geometry.solid import recipe_key
    from formgraph.kernels.brep import exchange, stepread

    _, data = ctx.read(path)
    try:
        stepread.check(data)
        ctx.guard(stepread.count_entities(data), "STEP entities")
        found = stepread.read(data)
    except stepread.StepProblem as exc:
        raise InputError("path", f"{path!r}: cannot read it as STEP: {exc}") from None
    digest = hashlib.blake2b(data, digest_size=20).hexdigest()
    out = []
    for k, raw in enumerate(found):  # one solid each
        key = recipe_key("read.step", file=digest, index=k)
        out.append(Solid.of(exchange.from_bytes(raw), key))
    return out
