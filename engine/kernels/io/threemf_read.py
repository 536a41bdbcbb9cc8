"""3MF packages read with a streaming XML parser: linear in the file, budgeted before
anything is expanded.

A 3MF file is a zip (Open Packaging Conventions) whose root relationship names the model
part, XML in the 3MF core namespace (3MF Core Specification 1.3, chapters 3-4): objects
holding a mesh (``<vertices>``, ``<triangles>``) or components (other objects, each with a
transform), and a ``<build>`` of items placing objects. Read here as well: the Materials and
Properties extension's colour groups and the core's base materials (vertex colours), and the
Production extension's ``p:path`` (a component or item naming an object in another model
part of the package, as Bambu Studio and PrusaSlicer write them).

The model is parsed by expat (the standard library's ``pyexpat``) fed from the zip one
megabyte at a time, names resolved through their namespaces, so ``p:x`` is never ``x`` and
an element of an extension we do not read is passed over with what it holds. A DTD or an
entity declaration is refused the moment expat sees it (3MF has none; this is what
defusedxml's guards do, here without the dependency). The hot elements (vertex, triangle,
colour, item) are collected as expat's attribute lists and turned into arrays once per
megabyte fed, in bulk (:func:`.textscan.parse_floats`), so memory stays near the output's.

This module opens the package (the root relationship, the parts a ``p:path`` names, each
streamed against the byte budget); :mod:`.threemf_model` parses a model part,
:mod:`.threemf_build` counts and expands the build.

Budgets, checked before the cost they bound:

- the package's members may claim at most ``max_bytes`` uncompressed, and the model parts
  are counted as they unpack, so a member lying about its size stops at the cap too;
- the vertices and triangles parsed may not pass ``max_elements``;
- the build is counted before it is expanded: the triangles and vertices every item places,
  through every level of components, and the number of placed meshes, are multiplied out
  over the object graph (cycles refused) and refused past ``max_elements``; only then are
  the copies made, one vectorized transform per mesh object for all its placements.
"""

from __future__ import annotations

import io
import zipfile
from urllib.parse import unquote
from xml.parsers import expat

from .threemf_build import Read3MF, build
from .threemf_model import MODEL_REL, RELS, Part, parser, qualified

__all__ = ["MAX_ELEMENTS", "MAX_MODEL_BYTES", "Read3MF", "read_3mf"]

MAX_MODEL_BYTES = 1 << 30  # uncompressed model parts, all together: the engine's input cap
MAX_ELEMENTS = 50_000_000
_CHUNK = 1 << 20


def read_3mf(
    data: bytes, max_bytes: int = MAX_MODEL_BYTES, max_elements: int = MAX_ELEMENTS
) -> Read3MF:
    """Every mesh a 3MF package's build places, transforms applied, joined into one mesh in
    millimetres, with vertex colours when every placed mesh has them (a colour group or base
    materials its triangles' corners, or the object, point into).

    Parameters
    ----------
    data : bytes
        The package.
    max_bytes : int
        The uncompressed model parts' budget, claimed and counted.
    max_elements : int
        The element budget: vertices and triangles parsed, and vertices, triangles and mesh
        placements the build makes.

    Returns
    -------
    Read3MF

    Raises
    ------
    ValueError
        Not a zip or no model part; a part over ``max_bytes``; XML that is not well formed,
        a DTD or an entity; an element out of place; a required extension we do not read;
        a malformed number, index, colour or transform (naming the object); a reference to
        an object that is not there, or a cycle of components; a build over the budget.
    """
    try:
        z = zipfile.ZipFile(io.BytesIO(data))
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise ValueError(f"not a 3MF package (a zip): {exc}") from None
    with z:
        members = {i.filename.lstrip("/"): i for i in z.infolist()}
        claimed = sum(i.file_size for i in members.values())
        if claimed > max_bytes:
            raise ValueError(
                f"the package's members claim {claimed:,} bytes uncompressed, over the budget "
                f"of {max_bytes:,}: refused (a zip bomb?)"
            )
        budget = _Budget(max_bytes, max_elements)
        root = _root_part(z, members, budget)
        parts = {root: Part(root, True, budget).parse(_stream(z, members[root], budget))}
        wanted = sorted({p for p, _ in parts[root].references()} - {root})
        for name in wanted:
            info = members.get(name) or members.get(unquote(name))
            if info is None:
                raise ValueError(f"a p:path names the model part {name!r}, which is not there")
            parts[name] = Part(name, False, budget).parse(_stream(z, info, budget))
    return build(parts, root, max_elements)


class _Budget:
    """Bytes unpacked and elements parsed so far, against their caps."""

    def __init__(self, max_bytes: int, max_elements: int):
        self.bytes, self.max_bytes = 0, max_bytes
        self.elements, self.max_elements = 0, max_elements

    def unpacked(self, n: int, name: str) -> None:
        self.bytes += n
        if self.bytes > self.max_bytes:
            raise ValueError(
                f"{name!r} unpacks to more than {self.max_bytes:,} bytes (the model parts' "
                "budget): refused"
            )

    def parsed(self, n: int) -> None:
        self.elements += n
        if self.elements > self.max_elements:
            raise ValueError(
                f"the model holds more than {self.max_elements:,} vertices and triangles, over "
                "the budget"
            )


def _stream(z: zipfile.ZipFile, info: zipfile.ZipInfo, budget: _Budget):
    """A member's bytes a megabyte at a time, counted against the budget as they unpack
    (whatever its header claims)."""
    try:
        with z.open(info) as fh:
            while chunk := fh.read(_CHUNK):
                budget.unpacked(len(chunk), info.filename)
                yield chunk
    except (zipfile.BadZipFile, OSError, EOFError, NotImplementedError, RuntimeError) as exc:
        raise ValueError(f"cannot unpack {info.filename!r}: {exc}") from None


def _root_part(z: zipfile.ZipFile, members: dict, budget: _Budget) -> str:
    """The model part the package's root relationship names (3D/3dmodel.model without one)."""
    name = "3D/3dmodel.model"
    if "_rels/.rels" in members:
        found: list[str] = []

        def start(tag: str, attrs: list) -> None:
            if tag in (qualified(RELS, "Relationship"), "Relationship"):
                a = dict(zip(attrs[0::2], attrs[1::2], strict=True))
                if a.get("Type") == MODEL_REL:
                    found.append(a.get("Target", ""))

        p = parser()
        p.StartElementHandler = start
        try:
            for chunk in _stream(z, members["_rels/.rels"], budget):
                p.Parse(chunk, False)
            p.Parse(b"", True)
        except expat.ExpatError as exc:
            raise ValueError(f"the package's _rels/.rels is not well-formed XML: {exc}") from None
        if found:
            name = unquote(found[0]).lstrip("/")
    if name not in members:
        raise ValueError(f"the package has no model part {name!r}")
    return name
