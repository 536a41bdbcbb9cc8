"""Cache keys: what went into a node, as one canonical text and its hash.

A node's key hashes its type, implementation version, canonical literal inputs and the keys
of its wired inputs (:mod:`formgraph.evaluation.run` assembles the parts), never the data
its inputs will make. Python values are keyed by content: a geometry value by a hash made
once and kept with it (it is immutable), a long literal list by its text written once
(:class:`Keyed`), arrays by their bytes in one call, an input file by the hash of its
bytes (:class:`InputKeys`).
"""

from __future__ import annotations

import enum
import hashlib
import json
import os
import stat
import uuid
import weakref
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..core import safety
from ..core.errors import PathError, Problem, Where
from ..geometry import Geometry

__all__ = [
    "KEYED_INLINE",
    "InputKeys",
    "Keyed",
    "canonical",
    "digest",
    "key_of",
    "key_text",
]


def canonical(value: Any) -> Any:
    """A JSON-able, order-stable form of a literal input (for cache keys)."""
    t = type(value)  # exact types first: the common case, and no str-Enum mistaken for str
    if t is str or t is int or t is bool or value is None:
        return value
    if t is float:
        return {"f": value.hex()}
    if t is dict:
        return {str(k): canonical(v) for k, v in sorted(value.items())}
    if t is list:
        return [canonical(v) for v in value]
    if isinstance(value, enum.Enum):
        return {"enum": str(value.value)}
    if isinstance(value, (bool, int, str)) or value is None:
        return value
    if isinstance(value, float):
        return {"f": value.hex()}
    if isinstance(value, np.generic):
        return canonical(value.item())
    if isinstance(value, np.ndarray):
        return {"a": _dtype_name(value.dtype), "s": list(value.shape), "h": _hash_bytes(value)}
    if isinstance(value, (list, tuple)):
        return [canonical(v) for v in value]
    if isinstance(value, dict):
        return {str(k): canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, Geometry):
        h = digest(value)
        return {"g": type(value).__name__, "h": h if h is not None else _token(value)}
    if isinstance(value, Keyed):
        return json.loads(value.text)  # (its text is this canonical form's JSON)
    raise TypeError(f"cannot make a cache key of {type(value).__name__}")


_TOKENS: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()


def _token(value: Any) -> str:
    """A unique, never reused name for a value whose content cannot be hashed."""
    if value not in _TOKENS:
        _TOKENS[value] = "obj:" + uuid.uuid4().hex
    return _TOKENS[value]


class Keyed:
    """A value's key text, made once: :func:`key_text` writes it as it is.

    A graph's literal inputs do not change while the graph does not (a change replaces
    them), so a long one (a polyline's 1,200 points, each number written by ``float.hex``)
    is written once, not at every evaluation; and one longer than :data:`KEYED_INLINE`
    characters stands in its node's key as the hash of that text (its 60 kB are not
    hashed again with the rest of the key at every evaluation).
    """

    __slots__ = ("text",)

    def __init__(self, value: Any):
        text = key_text(value)
        if len(text) > KEYED_INLINE:
            h = hashlib.blake2b(text.encode(), digest_size=20).hexdigest()
            text = '{"keyed":"' + h + '"}'
        self.text = text


KEYED_INLINE = 256  # characters of a literal's key text written into its node's key


def key_of(parts: Any) -> str:
    """The cache key of ``parts``: a hash of the JSON text of ``canonical(parts)``."""
    return hashlib.blake2b(key_text(parts).encode(), digest_size=20).hexdigest()


def key_text(value: Any) -> str:
    """``json.dumps(canonical(value), sort_keys=True, separators=(",", ":"))``, in one pass.

    Every node's key is built from this text on every run, so the plain values that inputs
    are made of (str, int, bool, None, float, lists and str-keyed dicts of them) are written
    directly, the leaves of a container without a call of their own; anything else goes
    through `canonical` and `json`. The text is the same either way, so keys do not change.
    """
    t = type(value)
    if t is dict:
        try:
            keys = sorted(value)
        except TypeError:  # mixed key types: canonical says so
            return _JSON.encode(canonical(value))
        out = []
        for k in keys:
            if type(k) is not str:
                return _JSON.encode(canonical(value))
            v = value[k]
            tv = type(v)
            if tv is str:
                out.append(_quote(k) + ":" + _quote(v))
            elif tv is float:
                out.append(_quote(k) + ':{"f":"' + v.hex() + '"}')
            else:
                out.append(_quote(k) + ":" + key_text(v))
        return "{" + ",".join(out) + "}"
    if t is str:
        return _quote(value)
    if t is float:
        return '{"f":"' + value.hex() + '"}'
    if t is bool:
        return "true" if value else "false"
    if t is int:
        return str(value)
    if value is None:
        return "null"
    if t is list or t is tuple:
        return "[" + ",".join([key_text(v) for v in value]) + "]"
    if t is Keyed:
        return value.text
    return _JSON.encode(canonical(value))


_quote = json.encoder.encode_basestring_ascii  # what json.dumps writes a str as
_JSON = json.JSONEncoder(sort_keys=True, separators=(",", ":"))


_DTYPE_NAMES: dict[np.dtype, str] = {}


def _dtype_name(dtype: np.dtype) -> str:
    """``str(dtype)``, kept: numpy builds the name anew each time (3 us, twice an array of
    every key), and the few dtypes that occur are named once."""
    name = _DTYPE_NAMES.get(dtype)
    if name is None:
        name = str(dtype)
        if len(_DTYPE_NAMES) < 64:  # (structured dtypes could be many: not all kept)
            _DTYPE_NAMES[dtype] = name
    return name


def _hash_bytes(a: np.ndarray) -> str:
    h = hashlib.blake2b(digest_size=16)
    h.update(_dtype_name(a.dtype).encode() + str(a.shape).encode())
    h.update(np.ascontiguousarray(a).view(np.uint8).reshape(-1))
    return h.hexdigest()


def digest(value: Any) -> str | None:
    """A content hash of a value (a key's part for a Python input, early cutoff's test);
    None when not hashable.

    A geometry value is immutable, so its hash is made once and kept with it: a mesh
    handed to ``evaluate`` again, or keyed three times in one run (the key, and the state
    a run's keys are kept under), is not hashed again.
    """
    if isinstance(value, Geometry):
        kept = value.__dict__.get("_digest")
        if kept is not None:
            return kept
        try:
            h = key_of({"type": type(value).__name__, "state": value.fingerprint()})
        except (TypeError, NotImplementedError):
            return None
        object.__setattr__(value, "_digest", h)
        return h
    try:
        return key_of(value)
    except (TypeError, NotImplementedError):
        return None


class InputKeys:
    """Mixed into ``_Run`` (which holds ``g``, ``input_files`` and ``where``): an input
    file's part of a key."""

    g: Any
    input_files: dict[str, dict[str, tuple[Path, bytes]]]
    keyed_files: bool
    where: Callable[..., Where]

    def input_file(self, name: str, port: str, relpath: Any) -> Any:
        """The key part of an input file: its path and a hash of its bytes (kept for the
        node, which parses exactly the bytes its key holds).

        A file whose stamp (device, inode, size, modification and change times in ns) is
        the one it had when last hashed is not read again: a sweep plans every variant's
        keys, and watch every version's, without rereading a large scan each time.
        """
        if not isinstance(relpath, str):
            return relpath  # the check or the node says what is wrong with it
        self.keyed_files = True  # keys that hold file bytes: never replayed (_Run.remember)
        here = self.where(name, port)
        try:
            path = safety.resolve_input(self.g.input_root, relpath, self.g.input_base)
        except PathError as exc:
            raise PathError([Problem(here, p.message) for p in exc.problems]) from None
        stamp = input_stamp(path)
        memo = self.g._input_digests.get(str(path))
        if stamp is not None and memo is not None and memo[0] == stamp:
            return {"path": relpath, "bytes": memo[1]}
        try:
            data = safety.read_input(path)
        except PathError as exc:
            raise PathError(
                [Problem(here, f"cannot read input {relpath!r}: {p.message}") for p in exc.problems]
            ) from None
        self.input_files.setdefault(name, {})[relpath] = (path, data)
        digest = hashlib.blake2b(data, digest_size=20).hexdigest()
        if stamp is not None:  # taken before the read: a change during it shows next time
            if len(self.g._input_digests) > 10_000:
                self.g._input_digests.clear()
            self.g._input_digests[str(path)] = (stamp, digest)
        return {"path": relpath, "bytes": digest}


def input_stamp(path: Path) -> tuple[int, ...] | None:
    """What changes when an input file's bytes do (None for anything but a regular file)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)
