"""STEP files read into solids, budgeted before parsing and bounded in time and memory.

A STEP file is text whose entities (``#12=...;``) OCC's reader parses all into memory and
then translates; a file of ten million entities, or one whose translation loops, would hold
the run for as long as it took. So the entities are counted first, in one scan of the bytes
(:func:`count_entities`), against the run's budget; a file that does not begin as STEP or
does not end (truncated) is refused before OCC sees it; and OCC reads in a child process
(this module run with ``-m``) under a time limit and an address-space limit, handing back
the solids in OCC's binary format. What the child cannot read is said in words, never
OCC's own text.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile

__all__ = ["TIMEOUT", "StepProblem", "count_entities", "read"]

TIMEOUT = 120.0  # seconds a child may spend reading one file
MEMORY = 4 << 30  # bytes of address space the child may use
_ENTITY = re.compile(rb"#\d+\s*=")


class StepProblem(ValueError):
    """A STEP file that cannot be read, said in words."""


def count_entities(data: bytes) -> int:
    """How many entity instances (``#n =``) the file holds (an upper bound: the pattern
    inside a string counts too)."""
    return sum(1 for _ in _ENTITY.finditer(data))


def check(data: bytes) -> None:
    """Refuse bytes that are not a whole STEP file.

    Raises
    ------
    StepProblem
    """
    head = data[:256].lstrip()
    if not head.startswith(b"ISO-10303-21"):
        raise StepProblem("it is not a STEP file (it does not begin with ISO-10303-21;)")
    if b"DATA;" not in data:
        raise StepProblem("it has no DATA section: it is truncated or not a STEP model")
    if not data.rstrip().endswith(b"END-ISO-10303-21;"):
        raise StepProblem("it is truncated: it does not end with END-ISO-10303-21;")


def _limit() -> None:  # pragma: no cover - runs in the child
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def read(data: bytes, timeout: float | None = None) -> list[bytes]:
    """The solids of a STEP file, each in OCC's binary format (in the file's order).

    Raises
    ------
    StepProblem
        Not STEP, truncated, too slow, too large for memory, or holding no solid.
    """
    check(data)
    limit = TIMEOUT if timeout is None else timeout
    with tempfile.TemporaryDirectory(prefix="formgraph-step-") as tmp:
        src = os.path.join(tmp, "in.step")
        with open(src, "wb") as fh:
            fh.write(data)
        try:
            done = subprocess.run(
                [sys.executable, "-m", __name__, src, tmp],
                capture_output=True,
                timeout=limit,
                preexec_fn=_limit if os.name == "posix" else None,
                check=False,
            )
        except subprocess.TimeoutExpired:
            raise StepProblem(f"reading it took longer than {limit:g} s and was stopped") from None
        if done.returncode != 0:
            said = done.stdout.decode(errors="replace").strip().splitlines()
            if said and said[-1].startswith("formgraph: "):
                raise StepProblem(said[-1][len("formgraph: ") :])
            if done.returncode < 0 or b"MemoryError" in done.stderr or b"bad_alloc" in done.stderr:
                raise StepProblem("OpenCASCADE's reader ran out of memory or crashed on it")
            raise StepProblem("OpenCASCADE's reader could not make sense of it")
        names = sorted(
            (n for n in os.listdir(tmp) if n.startswith("solid-")),
            key=lambda n: int(n[6:-5]),
        )
        out = []
        for n in names:  # one file per solid
            with open(os.path.join(tmp, n), "rb") as fh:
                out.append(fh.read())
    return out


def _child(src: str, folder: str) -> int:  # pragma: no cover - runs in the child
    """Read ``src`` with OCC, write each solid to ``folder/solid-<k>.brep``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
    from OCP.BRepLib import BRepLib
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopoDS import TopoDS

    from . import exchange, occ

    def fail(words: str) -> int:
        print(f"formgraph: {words}")
        return 2

    reader = STEPControl_Reader()
    try:
        status = reader.ReadFile(src)
    except occ.FAILURES:
        return fail("OpenCASCADE's reader could not parse it")
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        return fail("OpenCASCADE's reader could not parse it (a malformed entity?)")
    try:
        if reader.TransferRoots() == 0:
            return fail("it holds no shape OpenCASCADE can translate")
        shape = reader.OneShape()
    except occ.FAILURES:
        return fail("OpenCASCADE could not translate its shapes")
    solids = occ.solids_of(shape)
    if not solids:  # a closed shell written without its solid: made one
        for s in occ.explore(shape, "shell"):
            if not s.Closed():
                continue
            try:
                made = BRepBuilderAPI_MakeSolid(TopoDS.Shell(s)).Solid()
                BRepLib.OrientClosedSolid_s(made)
            except occ.FAILURES:
                continue
            solids.append(made)
    if not solids:
        faces = len(occ.explore(shape, "face"))
        return fail(
            f"it holds no solid ({faces} faces in open shells or surfaces): read.step reads "
            "closed solids"
        )
    for k, s in enumerate(solids):
        with open(os.path.join(folder, f"solid-{k}.brep"), "wb") as fh:
            fh.write(exchange.to_bytes(s))
    return 0


if __name__ == "__main__":  # pragma: no cover - the child
    sys.exit(_child(sys.argv[1], sys.argv[2]))
