"""Caches of node results: in memory (LRU bounded by bytes) and on disk (content addressed).

Keys are computed from what went into a node (its type, implementation version, canonical
literal inputs and the keys of its wired inputs), never from the data. Values on disk are
plain ``.npz`` archives (``allow_pickle=False``) with a JSON description and a checksum of
the whole entry (description, numbers and arrays: :func:`entry_checksum`), so a truncated,
corrupt, edited or foreign entry is detected and recomputed, never trusted. Reading an
entry never inflates it past :data:`MAX_INFLATE` times its size on disk (the arrays' headers
are checked against the bytes that hold them before anything is allocated) and never parses
a description nested deeper than :data:`MAX_META_DEPTH`: a hostile entry is a miss, not a
``MemoryError`` or ``RecursionError``. The disk cache is bounded (2 GiB unless
``$FORMGRAPH_CACHE_MAX_SIZE`` says otherwise): reading an entry marks it used, and the least
recently used entries go first when it is pruned.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import re
import stat
import tempfile
import time
import zipfile
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..geometry import STORABLE, Geometry, from_state
from .keys import (  # noqa: F401  (the keys' home before keys.py; imported from here too)
    KEYED_INLINE,
    Keyed,
    _hash_bytes,
    canonical,
    digest,
    key_of,
    key_text,
)

FORMAT = 2  # 2: the checksum covers the description too (entry_checksum)
# Entries of format 2 are named <key>.npz (as they were when it was introduced); a later
# format names its own <key>.f<N>.npz, so releases of two formats sharing one folder (a team
# cache) each keep their entries instead of deleting the other's as foreign. The folder's
# size bound and pruning cover every format's entries, so an old format's fade by last use.
_FIRST_NAMED_FORMAT = 2
MAX_INFLATE = 16  # ours are stored uncompressed (1x); anything far beyond is hostile
MAX_META_DEPTH = 64  # ours nest a few levels per list of geometry


def sizeof(value: Any) -> int:
    if isinstance(value, Geometry):
        return value.nbytes + 200
    if isinstance(value, np.ndarray):
        return value.nbytes + 100
    if isinstance(value, (list, tuple)):
        return 64 + sum(sizeof(v) for v in value)
    return 64


class MemoryCache:
    """Least-recently-used cache of node outputs, bounded by their size in bytes."""

    def __init__(self, max_bytes: int = 1 << 30):
        self.max_bytes = max_bytes
        self._items: OrderedDict[str, tuple[Any, int]] = OrderedDict()
        self.bytes = 0

    def get(self, key: str) -> tuple[bool, Any]:
        item = self._items.get(key)
        if item is None:
            return False, None
        self._items.move_to_end(key)
        return True, item[0]

    def put(self, key: str, value: Any, size: int | None = None) -> None:
        size = sizeof(value) if size is None else size
        if key in self._items:
            self.bytes -= self._items.pop(key)[1]
        if size > self.max_bytes:
            return
        self._items[key] = (value, size)
        self.bytes += size
        while self.bytes > self.max_bytes:
            _, (_, s) = self._items.popitem(last=False)
            self.bytes -= s

    def size(self, key: str, value: Any) -> int:
        """The size ``put`` counted for ``key`` when it holds ``value``; else ``sizeof``."""
        item = self._items.get(key)
        return item[1] if item is not None and item[0] is value else sizeof(value)

    def __contains__(self, key: str) -> bool:
        return key in self._items

    def __len__(self) -> int:
        return len(self._items)

    def clear(self) -> None:
        self._items.clear()
        self.bytes = 0


class Unstorable(Exception):
    """A value the disk cache cannot hold (it is then simply not stored)."""


def _encode(value: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(value, Geometry):
        name = type(value).__name__
        if name not in STORABLE:
            raise Unstorable(name)
        return {"geom": name, "state": {k: _encode(v, arrays) for k, v in value.state().items()}}
    if isinstance(value, np.ndarray):
        ref = f"a{len(arrays)}"
        arrays[ref] = value
        return {"array": ref}
    if isinstance(value, (list, tuple)):
        return {"list": [_encode(v, arrays) for v in value]}
    if isinstance(value, (bool, int, str)) or value is None:
        return {"v": value}
    if isinstance(value, float):
        return {"f": value.hex()}
    raise Unstorable(type(value).__name__)


def entry_checksum(meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> str:
    """The checksum of a disk-cache entry: all of it, not only its arrays.

    A hash of the description (``meta`` without its ``"check"``, as canonical JSON: format,
    key, identity and the value's description with every number it holds, so a cached
    ``mesh.measure`` whose volume was edited no longer matches) and of every array (name,
    dtype, shape and bytes). An entry whose checksum differs is a miss, recomputed.
    """
    check = hashlib.blake2b(digest_size=16)
    described = {k: v for k, v in meta.items() if k != "check"}
    check.update(json.dumps(described, sort_keys=True, separators=(",", ":")).encode())
    for name in sorted(arrays):
        check.update(b"\0" + name.encode() + b"\0")
        check.update(_hash_bytes(arrays[name]).encode())
    return check.hexdigest()


def _write_entry(fh: Any, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """Write an entry (an ``.npz``: the description as ``meta``, then the arrays) straight
    into the open file ``fh``, an array at a time: no copy of the entry in memory."""
    meta_bytes = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(fh, meta=meta_bytes, **arrays)


def _decode(desc: Any, arrays: Any) -> Any:
    if "geom" in desc:
        state = {k: _decode(v, arrays) for k, v in desc["state"].items()}
        return from_state(desc["geom"], state)
    if "array" in desc:
        return arrays[desc["array"]]
    if "list" in desc:
        return [_decode(v, arrays) for v in desc["list"]]
    if "f" in desc:
        return float.fromhex(desc["f"])
    return desc["v"]


class DiskCache:
    """A content-addressed store of node outputs in a folder, shared between processes.

    Entries are written to a temp file and renamed into place, so concurrent writers of the
    same key each leave a whole file; a reader that finds a bad entry (truncated, corrupt,
    wrong checksum, unknown format) deletes it and reports a miss.

    No symlink inside the folder is ever followed (the folder itself may be one): a shard
    folder or entry that is a link is neither read, written through, pruned nor cleared,
    so a planted link cannot make ``cache clear`` delete, or a run write, files elsewhere.
    """

    def __init__(self, root: str | os.PathLike[str], max_bytes: int | None = None):
        self.root = Path(root)
        self.max_bytes = default_max_bytes() if max_bytes is None else max_bytes
        self._written = 0  # bytes written since this object last pruned

    def _path(self, key: str) -> Path:
        suffix = "" if FORMAT == _FIRST_NAMED_FORMAT else f".f{FORMAT}"
        return self.root / key[:2] / f"{key}{suffix}.npz"

    def _shard(self, key: str) -> Path | None:
        """The folder of ``key``'s entry, None when it is a symlink or not a folder."""
        shard = self.root / key[:2]
        try:
            st = os.lstat(shard)
        except OSError:
            return shard  # not there yet: put makes it
        return shard if stat.S_ISDIR(st.st_mode) else None

    def has(self, key: str) -> bool:
        """Whether an entry for ``key`` exists (not read, so not checked: a hint only)."""
        if self._shard(key) is None:
            return False
        try:
            return stat.S_ISREG(os.lstat(self._path(key)).st_mode)
        except OSError:
            return False

    def get(self, key: str) -> tuple[bool, Any]:
        hit, value, _ = self.get_entry(key)
        return hit, value

    def get_entry(self, key: str) -> tuple[bool, Any, str | None]:
        """(hit, value, identity recorded with it)."""
        path = self._path(key)
        if self._shard(key) is None:
            return False, None, None
        try:
            data = _read_entry(path)
        except OSError:
            return False, None, None
        _mark_used(path)
        try:
            arrays = _read_npz(data)
            # json's parser refuses absurd nesting itself (RecursionError, a miss); what it
            # accepts is checked before the recursive decoding below
            meta = json.loads(bytes(arrays.pop("meta")).decode())
            if _depth(meta) > MAX_META_DEPTH:
                raise ValueError("description nested too deeply")
            if meta.get("format") != FORMAT or meta.get("key") != key:
                raise ValueError("foreign entry")
            if meta.get("check") != entry_checksum(meta, arrays):
                raise ValueError("checksum mismatch")
            return True, _decode(meta["value"], arrays), meta.get("identity")
        except (
            ValueError,
            KeyError,
            IndexError,
            OSError,
            EOFError,
            zipfile.BadZipFile,
            TypeError,
            AttributeError,
            RecursionError,
            MemoryError,
        ):
            try:
                path.unlink()
            except OSError:
                pass
            return False, None, None

    def put(self, key: str, value: Any, identity: str | None = None) -> bool:
        arrays: dict[str, np.ndarray] = {}
        try:
            desc = _encode(value, arrays)
        except Unstorable:
            return False
        meta = {"format": FORMAT, "key": key, "value": desc, "identity": identity or key}
        meta["check"] = entry_checksum(meta, arrays)
        path = self._path(key)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            if self._shard(key) is None:
                return False  # a link planted in the cache: never write through it
            fd, tmp = tempfile.mkstemp(prefix=".", suffix=".tmp", dir=path.parent)
            try:
                with os.fdopen(fd, "wb") as fh:
                    _write_entry(fh, meta, arrays)
                    size = fh.tell()
                os.replace(tmp, path)
                self._account(size)
            except BaseException:
                try:
                    os.unlink(tmp)
                except OSError:
                    pass
                raise
        except OSError:
            return False  # a cache that cannot be written is only slower, never wrong
        return True

    # ------------------------------------------------------------------- bounds

    def _account(self, nbytes: int) -> None:
        """Prune back to the limit after every tenth of it written (by this process)."""
        self._written += nbytes
        if self._written > self.max_bytes // 10:
            self._written = 0
            self.prune(self.max_bytes)

    def entries(self) -> list[tuple[Path, int, float]]:
        """(path, size in bytes, last use) of every entry; a file that vanishes is skipped."""
        out = []
        for path in _entry_paths(self.root):
            try:
                st = path.stat()
            except OSError:
                continue
            out.append((path, st.st_size, st.st_mtime))
        return out

    def info(self) -> CacheInfo:
        """How many entries the cache holds, their total size and the limit."""
        entries = self.entries()
        times = [t for _, _, t in entries]
        return CacheInfo(
            self.root,
            len(entries),
            sum(s for _, s, _ in entries),
            self.max_bytes,
            min(times) if times else None,
            max(times) if times else None,
        )

    def prune(self, max_bytes: int | None = None) -> tuple[int, int]:
        """Delete least recently used entries until the rest fit in ``max_bytes``.

        Entries are touched when read (their modification time is their last use), so the
        order is least recently used first. Temp files a crashed writer left (older than an
        hour) go too. Safe while other processes use the cache: a reader of an entry just
        deleted simply misses and recomputes. Returns (entries deleted, bytes freed).
        """
        limit = self.max_bytes if max_bytes is None else max_bytes
        entries = sorted(self.entries(), key=lambda e: e[2])
        total = sum(s for _, s, _ in entries)
        removed = freed = 0
        for path, size, _ in entries:
            if total <= limit:
                break
            if _unlink(path):
                removed += 1
                freed += size
            total -= size
        _remove_stale_temps(self.root)
        return removed, freed

    def clear(self) -> tuple[int, int]:
        """Delete every entry (and only the cache's own files). Returns (entries, bytes)."""
        return self.prune(0)


@dataclass(frozen=True)
class CacheInfo:
    """What ``formgraph cache info`` reports."""

    root: Path
    entries: int
    bytes: int
    max_bytes: int
    oldest: float | None  # last-use times (seconds since the epoch)
    newest: float | None


DEFAULT_MAX_BYTES = 2 << 30
_ENTRY = re.compile(r"[0-9a-f]{40}(?:\.f[0-9]{1,4})?\.npz")  # a key, its format (see FORMAT)


def default_max_bytes() -> int:
    """The disk cache limit: ``$FORMGRAPH_CACHE_MAX_SIZE`` (e.g. ``10GiB``), else 2 GiB."""
    text = os.environ.get("FORMGRAPH_CACHE_MAX_SIZE")
    if not text:
        return DEFAULT_MAX_BYTES
    try:
        return parse_size(text)
    except ValueError:
        return DEFAULT_MAX_BYTES  # a bad setting must not break every run; the CLI says why


_UNITS = {
    "": 1,
    "b": 1,
    "k": 1 << 10,
    "kib": 1 << 10,
    "kb": 10**3,
    "m": 1 << 20,
    "mib": 1 << 20,
    "mb": 10**6,
    "g": 1 << 30,
    "gib": 1 << 30,
    "gb": 10**9,
    "t": 1 << 40,
    "tib": 1 << 40,
    "tb": 10**12,
}


def parse_size(text: str) -> int:
    """Bytes from a size as people write it: ``500M``, ``2GiB``, ``1.5 GB``, ``1048576``.

    K, M, G, T alone and KiB, MiB, ... are powers of 1024; KB, MB, ... powers of 1000.

    Raises
    ------
    ValueError
        With a sentence naming the text.
    """
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+)\s*([a-zA-Z]*)\s*", text)
    unit = m.group(2).lower() if m else None
    if m is None or unit not in _UNITS:
        raise ValueError(
            f"{text!r} is not a size; write bytes or a number with K, M, G, T "
            f"(1024s) or KB, MB, GB, TB (1000s), e.g. 2GiB or 500M"
        )
    return int(float(m.group(1)) * _UNITS[unit])


def _shards(root: Path) -> list[os.DirEntry[str]]:
    """The cache's shard folders (``xx/``), never a symlink to a folder."""
    try:
        return [d for d in os.scandir(root) if len(d.name) == 2 and d.is_dir(follow_symlinks=False)]
    except OSError:
        return []


def _entry_paths(root: Path) -> list[Path]:
    """The cache's own entry files (``xx/<key>.npz``, regular files, not links), nothing
    else in the folder."""
    out: list[Path] = []
    for d in _shards(root):
        try:
            entries = list(os.scandir(d.path))
        except OSError:
            continue
        out.extend(
            Path(e.path)
            for e in entries
            if _ENTRY.fullmatch(e.name)
            and e.name[:2] == d.name
            and e.is_file(follow_symlinks=False)
        )
    return out


def _remove_stale_temps(root: Path, age: float = 3600.0) -> None:
    now = time.time()
    for d in _shards(root):
        try:
            temps = [e for e in os.scandir(d.path) if e.name.startswith(".")]
        except OSError:
            continue
        for e in temps:
            try:
                if (
                    e.name.endswith(".tmp")
                    and e.is_file(follow_symlinks=False)
                    and now - e.stat(follow_symlinks=False).st_mtime > age
                ):
                    os.unlink(e.path)
            except OSError:
                pass


def _mark_used(path: Path) -> None:
    """Record a read as the entry's last use (its modification time), for LRU pruning."""
    try:
        os.utime(path, follow_symlinks=False)
    except (OSError, NotImplementedError):
        pass


def _read_entry(path: Path) -> bytes:
    """An entry's bytes, from a regular file only (never through a link, never a FIFO)."""
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(f"{path} is not a regular file")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            return fh.read()
    finally:
        os.close(fd)


def _unlink(path: Path) -> bool:
    try:
        os.unlink(path)
    except OSError:
        return False
    return True


def _read_npz(data: bytes) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` archive, read-only over immutable bytes, inflating at most
    :data:`MAX_INFLATE` times ``len(data)``.

    Raises
    ------
    ValueError, zipfile.BadZipFile
        For anything but plain arrays whose headers agree with their bytes.
    """
    allowed = max(len(data) * MAX_INFLATE, 1 << 16)
    out: dict[str, np.ndarray] = {}
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        infos = zf.infolist()
        if sum(i.file_size for i in infos) > allowed:  # declared sizes bound what is read
            raise ValueError("entry inflates too far")
        for info in infos:
            if not info.filename.endswith(".npy"):
                raise ValueError("not an array")
            out[info.filename[:-4]] = _read_npy(zf.read(info))
    return out


def _read_npy(raw: bytes) -> np.ndarray:
    fh = io.BytesIO(raw)
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
    else:
        raise ValueError(f"npy format {version}")
    if dtype.hasobject or any(not isinstance(n, int) or n < 0 for n in shape):
        raise ValueError("not a plain array")
    count = math.prod(shape)
    if count * dtype.itemsize != len(raw) - fh.tell():  # the header must agree with the data
        raise ValueError("array size does not match its header")
    a = np.frombuffer(raw, dtype=dtype, count=count, offset=fh.tell())
    return a.reshape(shape[::-1]).T if fortran else a.reshape(shape)


def _depth(value: Any) -> int:
    """How deeply parsed JSON nests, measured without recursion."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (list, dict)):
            deepest = max(deepest, d)
            stack.extend((c, d + 1) for c in (v.values() if isinstance(v, dict) else v))
    return deepest


def default_cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "formgraph"
