"""One 3MF model part, parsed by expat as its bytes arrive: objects, property groups, build
items, with every name resolved through its namespace.

The element table (:data:`_PARENTS`) says where each element of the 3MF core, and the
Materials extension's colour groups, may stand: anything else in those namespaces is an
error naming the line; an element of another namespace (or core metadata) is passed over
with all it holds. The bulk of a file, its vertices, triangles, colours and items, is read
by handlers swapped in for the block (:meth:`_Part._go_hot`) that only collect expat's
attribute lists, converted to arrays once per megabyte fed (:func:`_values`, then
:func:`.textscan.parse_floats` / :func:`.textscan.parse_ints`).
"""

from __future__ import annotations

from itertools import chain
from urllib.parse import unquote
from xml.parsers import expat

import numpy as np

from .textscan import parse_floats, parse_ints
from .threemf import UNITS
from .threemf_build import Components, MeshObject

__all__ = ["CORE", "MATERIAL", "MODEL_REL", "PRODUCTION", "RELS", "Part", "parser", "qualified"]

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
MATERIAL = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02"
PRODUCTION = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
MODEL_REL = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"
RELS = "http://schemas.openxmlformats.org/package/2006/relationships"
# extensions whose required presence changes nothing we read (colours from the materials
# extension are read; its textures and composites are not geometry)
_KNOWN_EXTENSIONS = {CORE, MATERIAL, PRODUCTION}
_SEP = " "  # expat's namespace separator: an element's name is "uri local"


def qualified(ns: str, local: str) -> str:
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
_KEYS = {qualified(CORE, k): k for k in _PARENTS if k not in ("colorgroup", "color")}
_KEYS.update({k: k for k in _PARENTS if k not in ("colorgroup", "color")})  # no namespace
_KEYS.update(
    {qualified(MATERIAL, "colorgroup"): "colorgroup", qualified(MATERIAL, "color"): "color"}
)
_P_PATH = qualified(PRODUCTION, "path")
_IDENTITY = np.vstack([np.eye(3), np.zeros(3)])
_PROPS = ("pid", "p1", "p2", "p3")


def parser() -> expat.XMLParserType:
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


class Part:
    """One model part's objects and build, parsed as its bytes arrive."""

    def __init__(self, name: str, is_root: bool, budget):
        self.name, self.is_root, self.budget = name, is_root, budget
        self.unit = 1.0
        self.objects: dict[int, MeshObject | Components] = {}
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
    def parse(self, chunks) -> Part:
        p = self.parser = parser()
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
        out = [c for o in self.objects.values() if isinstance(o, Components) for c in o.children]
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
        names = (qualified(MATERIAL if key == "color" else CORE, key), key)
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
            self.objects[oid] = MeshObject(v, t, props, obj["pid"], obj["pindex"])
        elif "children" in obj:
            children = obj["children"]
            transforms = np.array([m for _, m in children]).reshape(-1, 4, 3)
            self.objects[oid] = Components([c for c, _ in children], transforms)
        else:
            self.objects[oid] = Components([], np.zeros((0, 4, 3)))  # an empty object
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
