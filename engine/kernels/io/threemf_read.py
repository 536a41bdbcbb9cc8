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
from itertools import chain
from typing import NamedTuple
from urllib.parse import unquote
from xml.parsers import expat

import numpy as np

from .textscan import parse_floats, parse_ints
from .threemf import UNITS

__all__ = ["MAX_MODEL_BYTES", "Read3MF", "read_3mf"]

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
MATERIAL = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02"
PRODUCTION = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
MODEL_REL = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"
RELS = "http://schemas.openxmlformats.org/package/2006/relationships"
# extensions whose required presence changes nothing we read (colours from the materials
# extension are read; its textures and composites are not geometry)
_KNOWN_EXTENSIONS = {CORE, MATERIAL, PRODUCTION}
MAX_MODEL_BYTES = 1 << 30  # uncompressed model parts, all together: the engine's input cap
MAX_ELEMENTS = 50_000_000
_CHUNK = 1 << 20
_SEP = " "  # expat's namespace separator: an element's name is "uri local"


class Read3MF(NamedTuple):
    """What a 3MF package builds, every item placed and joined, in millimetres."""

    vertices: np.ndarray  # (n, 3) float64
    triangles: np.ndarray  # (t, 3) int64
    colors: np.ndarray | None  # (n, 4) RGBA in 0..1 when every placed mesh has colours
    items: int  # build items


def _q(ns: str, local: str) -> str:
    return ns + _SEP + local


# where each element we read may stand (its parent): anything else in these namespaces is
# an error; an element of another namespace (or a core one we do not read, like metadata)
# is passed over with its content
_PARENTS = {
    "model": (None,),
    "resources": ("model",),
    "build": ("model",),
    "object": ("resources",),
    "mesh": ("object",),
    "vertices": ("mesh",),
    "vertex": ("vertices",),
    "triangles": ("mesh",),
    "triangle": ("triangles",),
    "components": ("object",),
    "component": ("components",),
    "item": ("build",),
    "basematerials": ("resources",),
    "base": ("basematerials",),
    "colorgroup": ("resources",),
    "color": ("colorgroup",),
}
_KEYS = {_q(CORE, k): k for k in _PARENTS if k not in ("colorgroup", "color")}
_KEYS.update({k: k for k in _PARENTS if k not in ("colorgroup", "color")})  # no namespace
_KEYS.update({_q(MATERIAL, "colorgroup"): "colorgroup", _q(MATERIAL, "color"): "color"})
_P_PATH = _q(PRODUCTION, "path")
_IDENTITY = np.vstack([np.eye(3), np.zeros(3)])
_PROPS = ("pid", "p1", "p2", "p3")


class _Mesh(NamedTuple):
    vertices: np.ndarray  # (n, 3), millimetres
    triangles: np.ndarray  # (t, 3)
    props: np.ndarray | None  # (t, 4): the triangle's pid, p1, p2, p3 (-1: not given)
    pid: int  # the object's property group (-1: none)
    pindex: int


class _Components(NamedTuple):
    children: list  # (part, objectid) per component
    transforms: np.ndarray  # (k, 4, 3), translations in millimetres


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
        parts = {root: _Part(root, True, budget).parse(_stream(z, members[root], budget))}
        wanted = sorted({p for p, _ in parts[root].references()} - {root})
        for name in wanted:
            info = members.get(name) or members.get(unquote(name))
            if info is None:
                raise ValueError(f"a p:path names the model part {name!r}, which is not there")
            parts[name] = _Part(name, False, budget).parse(_stream(z, info, budget))
    return _build(parts, root, max_elements)


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
            if tag in (_q(RELS, "Relationship"), "Relationship"):
                a = dict(zip(attrs[0::2], attrs[1::2], strict=True))
                if a.get("Type") == MODEL_REL:
                    found.append(a.get("Target", ""))

        parser = _parser()
        parser.StartElementHandler = start
        try:
            for chunk in _stream(z, members["_rels/.rels"], budget):
                parser.Parse(chunk, False)
            parser.Parse(b"", True)
        except expat.ExpatError as exc:
            raise ValueError(f"the package's _rels/.rels is not well-formed XML: {exc}") from None
        if found:
            name = unquote(found[0]).lstrip("/")
    if name not in members:
        raise ValueError(f"the package has no model part {name!r}")
    return name


def _parser() -> expat.XMLParserType:
    """An expat parser with namespaces resolved, attributes as flat lists, and every DTD,
    entity declaration and external reference refused (3MF has none)."""
    p = expat.ParserCreate(namespace_separator=_SEP)
    p.ordered_attributes = True
    p.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)

    def refuse(*_):
        raise ValueError("the XML declares a DTD or an entity; 3MF has none (refused)")

    p.StartDoctypeDeclHandler = refuse
    p.EntityDeclHandler = refuse
    p.UnparsedEntityDeclHandler = refuse
    p.ExternalEntityRefHandler = refuse
    return p


class _Part:
    """One model part's objects and build, parsed as its bytes arrive."""

    def __init__(self, name: str, is_root: bool, budget: _Budget):
        self.name, self.is_root, self.budget = name, is_root, budget
        self.unit = 1.0
        self.objects: dict[int, _Mesh | _Components] = {}
        self.groups: dict[int, np.ndarray] = {}  # property group id -> (k, 4) RGBA
        self.item_rows: list[list] = []
        self.items: list[tuple[np.ndarray, np.ndarray, list]] = []  # (ids, transforms, paths)
        self.stack: list[str | None] = []  # the open elements we read (None: passed over)
        self.skip = 0  # depth inside an element passed over
        self.rows: list[list] = []  # the hot element's attribute lists, not yet converted
        self.chunks: list[np.ndarray] = []  # the current block's converted rows
        self.hot: str | None = None  # which element self.rows holds
        self.obj: dict = {}  # the object being read
        self.namespaces: dict[str, str] = {}  # prefix -> URI, as declared
        self.seen_model = False

    # -- feeding ------------------------------------------------------------------------------
    def parse(self, chunks) -> _Part:
        p = self.parser = _parser()
        p.StartElementHandler = self._start
        p.EndElementHandler = self._end
        p.StartNamespaceDeclHandler = self.namespaces.__setitem__
        try:
            for chunk in chunks:
                p.Parse(chunk, False)
                self._flush()  # the megabyte's rows as arrays: memory near the output's
                self._flush_items()
            p.Parse(b"", True)
            self._flush()
        except expat.ExpatError as exc:
            raise ValueError(f"{self.name!r} is not well-formed XML: {exc}") from None
        if not self.seen_model:
            raise ValueError(f"{self.name!r} has no <model> element")
        self._flush_items()
        return self

    def references(self) -> list[tuple[str, int]]:
        """The (part, object id) pairs this part's components and items name."""
        out = [c for o in self.objects.values() if isinstance(o, _Components) for c in o.children]
        for ids, _, paths in self.items:
            if any(paths):
                out += [(p or self.name, int(i)) for i, p in zip(ids, paths, strict=True)]
            else:  # the common case: every item in this part, a few distinct objects
                out += [(self.name, int(i)) for i in np.unique(ids)]
        return out

    # -- elements -----------------------------------------------------------------------------
    def _start(self, name: str, attrs: list) -> None:
        if self.skip:
            self.skip += 1
            return
        key = _KEYS.get(name)
        parent = self.stack[-1] if self.stack else None
        if key is None:
            if not self.stack:
                raise ValueError(
                    f"{self.name!r}: the root element is <{_shown(name)}>, not a 3MF <model>"
                )
            self.skip = 1  # an extension's element (or metadata): passed over, content too
            return
        if parent not in _PARENTS[key]:
            where = f"inside <{parent}>" if parent else "as the root"
            raise ValueError(
                f"{self.name!r}, line {self.parser.CurrentLineNumber}: a <{key}> {where}, "
                "where the 3MF core does not put one"
            )
        self.stack.append(key)
        if key in ("vertex", "triangle", "color", "base"):
            self.rows.append(attrs)
            return
        if key == "item":
            self.item_rows.append(attrs)
            return
        getattr(self, "_open_" + key, _nothing)(_attrs(attrs))

    def _go_hot(self, key: str, rows: list) -> None:
        """Read the block just opened with handlers that only collect its ``key`` children's
        attribute lists into ``rows`` (the bulk of a file: kept to a few bytecodes each);
        anything else in the block hands back to the general handlers, which read on."""
        names = (_q(MATERIAL if key == "color" else CORE, key), key)
        append, p, depth = rows.append, self.parser, 0

        def start(name: str, attrs: list) -> None:
            nonlocal depth
            if not depth and name in names:
                append(attrs)
                depth = 1
                return
            cold()
            if depth:  # something inside the hot element: it is open
                self.stack.append(key)
            self._start(name, attrs)

        def end(name: str) -> None:
            nonlocal depth
            if depth:
                depth = 0
                return
            cold()  # the block closes
            self._end(name)

        def cold() -> None:
            p.StartElementHandler, p.EndElementHandler = self._start, self._end

        p.StartElementHandler, p.EndElementHandler = start, end

    def _end(self, name: str) -> None:
        if self.skip:
            self.skip -= 1
            return
        key = self.stack.pop()
        if key in ("vertex", "triangle", "color", "base", "item"):
            return
        getattr(self, "_close_" + key, _nothing)()

    def _open_model(self, a: dict) -> None:
        self.seen_model = True
        unit = a.get("unit", "millimeter")
        if unit not in UNITS:
            raise ValueError(f"{self.name!r}: unknown model unit {unit!r}")
        self.unit = UNITS[unit]
        required = a.get("requiredextensions", "").split()
        if required:  # prefixes, resolved through the declarations in force on <model>
            unknown = [p for p in required if self._namespace(p) not in _KNOWN_EXTENSIONS]
            if unknown:
                raise ValueError(
                    f"{self.name!r} requires the 3MF extension(s) "
                    f"{', '.join(repr(self._namespace(p) or p) for p in unknown)}, which "
                    "this reader does not read (the 3MF core says a consumer must refuse it)"
                )

    def _namespace(self, prefix: str) -> str | None:
        return self.namespaces.get(prefix or None)

    def _open_object(self, a: dict) -> None:
        self.obj = {
            "id": _int_attr(a, "id", self.name, "an <object>"),
            "pid": _int_attr(a, "pid", self.name, "an <object>", -1),
            "pindex": _int_attr(a, "pindex", self.name, "an <object>", 0),
        }

    def _close_object(self) -> None:
        obj = self.obj
        oid = obj["id"]
        if oid in self.objects:
            raise ValueError(f"{self.name!r}: two objects have the id {oid}")
        if "vertices" in obj:
            v, t, props = obj["vertices"], obj.get("triangles"), obj.get("props")
            t = np.zeros((0, 3), np.int64) if t is None else t
            if t.size and (t.min() < 0 or t.max() >= len(v)):
                raise ValueError(
                    f"{self.name!r}, object {oid}: a triangle refers to a vertex that does not "
                    f"exist ({len(v):,} vertices)"
                )
            self.objects[oid] = _Mesh(v, t, props, obj["pid"], obj["pindex"])
        elif "children" in obj:
            children = obj["children"]
            transforms = np.array([m for _, m in children]).reshape(-1, 4, 3)
            self.objects[oid] = _Components([c for c, _ in children], transforms)
        else:
            self.objects[oid] = _Components([], np.zeros((0, 4, 3)))  # an empty object
        self.obj = {}

    def _open_vertices(self, _: dict) -> None:
        self.hot = "vertex"
        self._go_hot("vertex", self.rows)

    def _close_vertices(self) -> None:
        self._flush()
        v = np.concatenate(self.chunks) if self.chunks else np.zeros((0, 3))
        self.obj["vertices"] = v * self.unit if self.unit != 1.0 else v
        self.chunks, self.hot = [], None

    def _open_triangles(self, _: dict) -> None:
        self.hot = "triangle"
        self._go_hot("triangle", self.rows)

    def _close_triangles(self) -> None:
        self._flush()
        rows = self.chunks
        self.obj["triangles"] = (
            np.concatenate([r[0] for r in rows]) if rows else np.zeros((0, 3), np.int64)
        )
        props = [r[1] for r in rows]
        if any(p is not None for p in props):
            full = [
                p if p is not None else np.full((len(r[0]), 4), -1, np.int64)
                for r, p in zip(rows, props, strict=True)
            ]
            self.obj["props"] = np.concatenate(full)
        self.chunks, self.hot = [], None

    def _open_components(self, _: dict) -> None:
        self.obj["children"] = []

    def _open_component(self, a: dict) -> None:
        path = a.get(_P_PATH)
        if path and not self.is_root:
            raise ValueError(
                f"{self.name!r}: a component with a p:path outside the root model part (the "
                "Production extension forbids it)"
            )
        oid = _int_attr(a, "objectid", self.name, "a <component>")
        m = _transform(a.get("transform"), self.name, self.unit)
        self.obj["children"].append(((_part_name(path) if path else self.name, oid), m))

    def _open_colorgroup(self, a: dict) -> None:
        self.obj = {"group": _int_attr(a, "id", self.name, "a <colorgroup>")}
        self.hot = "color"
        self._go_hot("color", self.rows)

    def _open_basematerials(self, a: dict) -> None:
        self.obj = {"group": _int_attr(a, "id", self.name, "a <basematerials>")}
        self.hot = "base"
        self._go_hot("base", self.rows)

    def _open_build(self, _: dict) -> None:
        self._go_hot("item", self.item_rows)

    def _close_colorgroup(self) -> None:
        self._flush()
        gid = self.obj["group"]
        if gid in self.groups:
            raise ValueError(f"{self.name!r}: two property groups have the id {gid}")
        self.groups[gid] = np.concatenate(self.chunks) if self.chunks else np.zeros((0, 4))
        self.chunks, self.hot, self.obj = [], None, {}

    _close_basematerials = _close_colorgroup

    # -- bulk conversion -----------------------------------------------------------------
    def _flush(self) -> None:
        """The collected rows of the hot element as arrays (one numpy pass per block)."""
        rows = self.rows.copy()  # the list itself stays: the hot handlers append to it
        self.rows.clear()
        if not rows:
            return
        if self.hot == "vertex":
            self.budget.parsed(len(rows))
            values, _ = _values(rows, ("x", "y", "z"), None, self.name, "vertex")
            self.chunks.append(self._numbers(values, len(rows), "a vertex coordinate", 3))
        elif self.hot == "triangle":
            self.budget.parsed(len(rows))
            self.chunks.append(self._triangles(rows))
        elif self.hot in ("color", "base"):
            key = "color" if self.hot == "color" else "displaycolor"
            values, _ = _values(rows, (key,), None, self.name, self.hot)
            self.chunks.append(_colors(values, self.name))

    def _triangles(self, rows: list) -> tuple[np.ndarray, np.ndarray | None]:
        n = len(rows)
        values, extra = _values(rows, ("v1", "v2", "v3"), _PROPS, self.name, "triangle")
        t = self._numbers(values, n, "a triangle's vertex index", 3, whole=True)
        if extra is None:
            return t, None
        if any(v.lstrip().startswith("-") for v in extra):
            raise ValueError(f"{self._where()}: a triangle's property index is negative")
        props = self._numbers([v or "-1" for v in extra], n, "a triangle's property", 4, whole=True)
        props[:, 2:] = np.where(props[:, 2:] < 0, props[:, 1:2], props[:, 2:])  # p2, p3: p1
        return t, props

    def _numbers(self, values, n, what, width, whole=False):
        text = np.frombuffer(" ".join(values).encode(), np.uint8)
        try:
            out = parse_ints(text, n * width) if whole else parse_floats(text, n * width)
        except ValueError as exc:
            raise ValueError(f"{self._where()}: {what}: {exc}") from None
        if not whole and not np.all(np.isfinite(out)):
            raise ValueError(f"{self._where()}: {what} is not a finite number")
        return out.reshape(n, width)

    def _where(self) -> str:
        oid = self.obj.get("id")
        return f"{self.name!r}, object {oid}" if oid is not None else repr(self.name)

    def _flush_items(self) -> None:
        """The collected items as arrays: object ids, (k, 4, 3) transforms, part paths."""
        rows = self.item_rows.copy()
        self.item_rows.clear()
        if not rows:
            return
        ids, extra = _values(rows, ("objectid",), ("transform", _P_PATH), self.name, "item")
        ids = self._numbers(ids, len(rows), "an item's objectid", 1, whole=True).ravel()
        if ids.size and ids.min() < 0:
            raise ValueError(f"{self.name!r}: an item's objectid is negative")
        transforms = np.empty((len(rows), 4, 3))
        transforms[:] = _IDENTITY
        paths: list = [None] * len(rows)
        if extra is not None:
            given = [k for k in range(len(rows)) if extra[2 * k]]
            if given:
                text = " ".join(extra[2 * k] for k in given)
                try:
                    m = parse_floats(np.frombuffer(text.encode(), np.uint8), 12 * len(given))
                except ValueError:
                    for k in given:  # name the one that is wrong
                        _transform(extra[2 * k], self.name, self.unit)
                    raise
                m = m.reshape(-1, 4, 3)
                if not np.isfinite(m).all():
                    raise ValueError(f"{self.name!r}: an item's transform is not finite numbers")
                m[:, 3] *= self.unit
                transforms[given] = m
            paths = [_part_name(p) if p else None for p in extra[1::2]]
            if any(paths) and not self.is_root:
                raise ValueError(f"{self.name!r}: a build item outside the root model part")
        self.items.append((ids, transforms, paths))


def _nothing(*_) -> None:
    return None


def _shown(name: str) -> str:
    uri, _, local = name.rpartition(_SEP)
    return f"{{{uri}}}{local}" if uri else local


def _attrs(flat: list) -> dict:
    return dict(zip(flat[0::2], flat[1::2], strict=True))


def _part_name(path: str) -> str:
    return unquote(path).lstrip("/")


def _int_attr(a: dict, key: str, part: str, what: str, default: int | None = None) -> int:
    text = a.get(key)
    if text is None:
        if default is None:
            raise ValueError(f"{part!r}: {what} has no {key}")
        return default
    try:
        value = int(text.strip())
    except ValueError:
        raise ValueError(f"{part!r}: {what}'s {key} {text[:40]!r} is not a whole number") from None
    if value < 0:
        raise ValueError(f"{part!r}: {what}'s {key} {value} is negative")
    return value


def _transform(text: str | None, part: str, unit: float) -> np.ndarray:
    """A 3MF transform ``m00 m01 m02 m10 ... m32`` as a (4, 3) matrix: p' = p @ M[:3] + M[3],
    its translation in millimetres."""
    if text is None:
        return _IDENTITY
    try:
        values = np.array(text.split(), dtype=float)
    except ValueError:
        values = np.zeros(0)
    if values.size != 12 or not np.all(np.isfinite(values)):
        raise ValueError(f"{part!r}: a transform needs 12 finite numbers, got {text[:60]!r}")
    m = values.reshape(4, 3)
    m[3] *= unit
    return m


def _values(rows: list, names: tuple, optional: tuple | None, part: str, tag: str):
    """The named attributes' values of every row, in row-major order (a flat list of
    strings), and the ``optional`` ones' (``''`` where a row lacks one) or None when no row
    has any.

    Rows written as ``names`` (then ``optional``) in order, what writers do, are taken in
    C-level list operations; any other row (attributes reordered, extra or namespaced ones)
    goes by name.
    """
    n, w = len(rows), len(names)
    flat = list(chain.from_iterable(rows))
    keys = flat[0::2]
    if len(flat) == 2 * w * n and keys == list(names) * n:
        return flat[1::2], None
    layout = rows[0][0::2] if rows else []
    if len(flat) == len(layout) * 2 * n and keys == layout * n and set(names) <= set(layout):
        # every row has the same attributes in the same order (what a writer makes: p:UUID,
        # properties, ...): columns picked by position in one array operation
        table = np.array(flat[1::2], dtype=object).reshape(n, len(layout))
        values = table[:, [layout.index(k) for k in names]].ravel().tolist()
        if not optional or not set(optional) & set(layout):
            return values, None
        cols = [layout.index(k) if k in layout else None for k in optional]
        extra = np.full((n, len(optional)), "", dtype=object)
        for j, c in enumerate(cols):
            if c is not None:
                extra[:, j] = table[:, c]
        return values, extra.ravel().tolist()
    values: list[str] = []
    extra: list[str] = []
    for row in rows:
        a = _attrs(row)
        try:
            values += [a[k] for k in names]
        except KeyError as exc:
            raise ValueError(f"{part!r}: a <{tag}> has no {exc.args[0]}") from None
        if optional:
            extra += [a.get(k, "") for k in optional]
    return values, (extra if optional and any(extra) else None)


def _colors(values: list[str], part: str) -> np.ndarray:
    """``#RRGGBB`` or ``#RRGGBBAA`` strings as (k, 4) RGBA in 0..1."""
    full = [v + "FF" if len(v) == 7 else v for v in (s.strip() for s in values)]
    text = "".join(full)
    if len(text) != 9 * len(full) or text[0::9] != "#" * len(full):
        bad = next(v for v in full if len(v) != 9 or v[0] != "#")
        raise ValueError(f"{part!r}: a colour {bad[:20]!r} is not #RRGGBB or #RRGGBBAA")
    try:
        raw = bytes.fromhex(text.replace("#", ""))
    except ValueError:
        raise ValueError(f"{part!r}: a colour holds a digit that is not hexadecimal") from None
    return np.frombuffer(raw, np.uint8).reshape(-1, 4) / 255.0


# --------------------------------------------------------------------------------------------
# the build: counted over the object graph, then expanded


def _build(parts: dict[str, _Part], root: str, max_elements: int) -> Read3MF:
    objects: dict[tuple[str, int], _Mesh | _Components] = {
        (name, oid): o for name, part in parts.items() for oid, o in part.objects.items()
    }
    top = parts[root]
    ids = np.concatenate([i for i, _, _ in top.items]) if top.items else np.zeros(0, np.int64)
    transforms = np.concatenate([m for _, m, _ in top.items]) if top.items else np.zeros((0, 4, 3))
    # the items' objects as codes into the few distinct (part, id) pairs: every step below
    # is an array operation over the items, however many millions
    if any(p for _, _, ps in top.items for p in ps):  # Production items naming other parts
        names = [p or root for _, _, ps in top.items for p in ps]
        _, part_code = np.unique(np.array(names, dtype=object), return_inverse=True)
        pair = part_code.astype(np.int64) * (int(ids.max(initial=0)) + 1) + ids
    else:
        names, pair = None, ids
    _, first, item_code = np.unique(pair, return_index=True, return_inverse=True)
    keys = [(names[k] if names else root, int(ids[k])) for k in first]
    for key in keys:
        if key not in objects:
            raise ValueError(f"a build item names object {key[1]} ({key[0]!r}), which is not there")
    order = _topological(objects, set(keys))
    # what one placement of each object makes: vertices, triangles, placements (Python
    # ints: a fan-out multiplies past int64 long before it is refused)
    size: dict = {}
    for key in reversed(order):
        o = objects[key]
        if isinstance(o, _Mesh):
            size[key] = (len(o.vertices), len(o.triangles), 1)
        else:  # every placement counts, an object of components too: each costs work
            size[key] = (*(sum(size[c][k] for c in o.children) for k in range(2)),
                         1 + sum(size[c][2] for c in o.children))  # fmt: skip
    counts = np.bincount(item_code, minlength=len(keys))
    totals = [sum(int(n) * size[k][j] for k, n in zip(keys, counts, strict=True)) for j in range(3)]
    if max(totals) > max_elements:
        raise ValueError(
            f"the build places {totals[1]:,} triangles and {totals[0]:,} vertices in "
            f"{totals[2]:,} object placements (from {len(item_code):,} build items through "
            f"their components), over the budget of {max_elements:,}: refused before expanding"
        )
    nv, nt = totals[0], totals[1]
    # each placement of an object: its transform and where its vertices and triangles go
    per_v = np.array([size[k][0] for k in keys], np.int64)[item_code]
    per_t = np.array([size[k][1] for k in keys], np.int64)[item_code]
    starts_v, starts_t = np.cumsum(per_v) - per_v, np.cumsum(per_t) - per_t
    placed: dict = {}
    if len(keys) == 1:  # every item places the same object: no gathered copies
        placed[keys[0]] = [(transforms, starts_v, starts_t)]
    else:
        grouped = np.argsort(item_code, kind="stable")
        bounds = np.concatenate([[0], np.cumsum(counts)])
        for u, key in enumerate(keys):
            w = grouped[bounds[u] : bounds[u + 1]]
            placed[key] = [(transforms[w], starts_v[w], starts_t[w])]
    del transforms, starts_v, starts_t, per_v, per_t
    top.items = []  # the items' arrays live on in the placements only
    out_v = np.empty((nv, 3))
    out_t = np.empty((nt, 3), np.int64)
    colors = _Colors(parts, nv)
    for key in order:
        batches = placed.pop(key, [])
        if not batches:
            continue
        if len(batches) == 1:
            m, sv, st = batches[0]
        else:
            m, sv, st = (np.concatenate([b[j] for b in batches]) for j in range(3))
        del batches
        o = objects[key]
        if isinstance(o, _Mesh):
            _place(o, m, sv, st, out_v, out_t)
            colors.place(key, o, sv)
            continue
        dv = dt = 0
        for child, c in zip(o.children, o.transforms, strict=True):
            # the child's placement: its component transform, then the parent's
            full = np.concatenate([c[:3] @ m[:, :3], (c[3] @ m[:, :3] + m[:, 3])[:, None]], 1)
            if size[child][0] or size[child][1]:  # nothing to place in an empty one
                placed.setdefault(child, []).append((full, sv + dv, st + dt))
            dv, dt = dv + size[child][0], dt + size[child][1]
    return Read3MF(out_v, out_t, colors.result(), len(item_code))


def _topological(objects: dict, roots: set) -> list:
    """The objects reachable from ``roots``, every parent before its components; a cycle is
    refused (iteratively: no recursion however deep the components nest)."""
    state: dict = {}  # 1: on the path, 2: done
    post: list = []
    for root in sorted(roots, key=str):
        if root in state:
            continue
        stack = [(root, iter(_children(objects, root)))]
        state[root] = 1
        while stack:
            key, it = stack[-1]
            child = next(it, None)
            if child is None:
                stack.pop()
                state[key] = 2
                post.append(key)
                continue
            if child not in objects:
                raise ValueError(
                    f"object {key[1]} ({key[0]!r}) has a component naming object {child[1]} "
                    f"({child[0]!r}), which is not there"
                )
            if state.get(child) == 1:
                raise ValueError(
                    f"object {child[1]} ({child[0]!r}) contains itself through its components "
                    "(a cycle)"
                )
            if child not in state:
                state[child] = 1
                stack.append((child, iter(_children(objects, child))))
    return post[::-1]


def _children(objects: dict, key) -> list:
    o = objects[key]
    return list(dict.fromkeys(o.children)) if isinstance(o, _Components) else []


def _place(o: _Mesh, m: np.ndarray, sv: np.ndarray, st: np.ndarray, out_v, out_t) -> None:
    """Every placement of one mesh, in one vectorized pass: (k, n, 3) copies written where
    each placement's vertices and triangles go (straight into the output when the
    placements follow one another there, as the items of one object do)."""
    n, t, k = len(o.vertices), len(o.triangles), len(m)
    if n:
        if _consecutive(sv, n):
            view = out_v[sv[0] : sv[0] + k * n].reshape(k, n, 3)
            np.einsum("nj,kji->kni", o.vertices, m[:, :3], out=view)
            view += m[:, None, 3]
        else:
            copies = np.einsum("nj,kji->kni", o.vertices, m[:, :3]) + m[:, None, 3]
            out_v[(sv[:, None] + np.arange(n)).ravel()] = copies.reshape(-1, 3)
    if t:
        if _consecutive(st, t):
            view = out_t[st[0] : st[0] + k * t].reshape(k, t, 3)
            np.add(o.triangles[None], sv[:, None, None], out=view)
        else:
            copies = (o.triangles[None] + sv[:, None, None]).reshape(-1, 3)
            out_t[(st[:, None] + np.arange(t)).ravel()] = copies


def _consecutive(starts: np.ndarray, size: int) -> bool:
    """Whether placement i starts ``size`` after placement i - 1, for every i."""
    return bool(starts.size) and bool(np.all(np.diff(starts) == size))


class _Colors:
    """A colour a placed vertex, from the property groups its mesh's triangles and object
    point into; None unless every placed mesh has colours."""

    def __init__(self, parts: dict[str, _Part], n: int):
        self.parts = parts
        self.out = np.zeros((n, 4))
        self.complete = n > 0
        self.cache: dict = {}

    def place(self, key, o: _Mesh, starts: np.ndarray) -> None:
        if not self.complete:
            return
        if key not in self.cache:
            self.cache[key] = _mesh_colors(self.parts[key[0]], key[1], o)
        c = self.cache[key]
        if c is None:
            self.complete = False
            return
        self.out[(starts[:, None] + np.arange(len(c))).ravel()] = np.tile(c, (len(starts), 1))

    def result(self) -> np.ndarray | None:
        return self.out if self.complete else None


def _mesh_colors(part: _Part, oid: int, o: _Mesh) -> np.ndarray | None:
    """A colour a vertex of one mesh object, or None when it has none: the object's default
    (its pid and pindex) where its triangles name none, each corner's where they do."""
    groups, n = part.groups, len(o.vertices)
    out = np.zeros((n, 4))
    has_default = o.pid in groups
    if has_default:
        group = groups[o.pid]
        if not 0 <= o.pindex < len(group):
            raise ValueError(
                f"{part.name!r}, object {oid}: its pindex {o.pindex} is outside its property "
                f"group ({len(group)} entries)"
            )
        out[:] = group[o.pindex]
    if o.props is None:
        return out if has_default else None
    pid = np.where(o.props[:, 0] >= 0, o.props[:, 0], o.pid)
    given = o.props[:, 1] >= 0
    if not has_default and not (given & np.isin(pid, list(groups))).all():
        return None  # some corner has no colour to take
    for gid in np.unique(pid[given]):
        if gid not in groups:
            continue  # a texture or composite group: no colour of its own
        rows = given & (pid == gid)
        idx = o.props[rows, 1:]
        group = groups[int(gid)]
        if idx.max(initial=0) >= len(group):
            raise ValueError(
                f"{part.name!r}, object {oid}: a triangle's colour index is outside property "
                f"group {gid} ({len(group)} entries)"
            )
        out[o.triangles[rows].ravel()] = group[idx.ravel()]
    return out
