"""Writing files safely: atomically, and only inside the output directory.

A graph downloaded from someone else must not write anywhere but the output directory, so
every export path is relative, free of ``..``, and still inside the directory after symlinks
are followed. Files appear whole or not at all (temp file in the same folder, fsync,
``os.replace``), and a file that already holds exactly the bytes is left untouched.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path, PurePosixPath, PureWindowsPath

from .errors import PathError


def path_problem(relpath: str) -> str | None:
    """Why ``relpath`` may not be an output path, or None when it may (no file access)."""
    if not isinstance(relpath, str) or not relpath.strip():
        return "an output path must be a non-empty relative path"
    if "\x00" in relpath:
        return "an output path must not contain NUL characters"
    posix, win = PurePosixPath(relpath), PureWindowsPath(relpath)
    if (
        posix.is_absolute()
        or win.is_absolute()
        or win.drive
        or relpath.startswith(("/", "\\", "~"))
    ):
        return f"output path {relpath!r} is absolute; give a path relative to the output directory"
    if ".." in posix.parts or ".." in win.parts:
        return f"output path {relpath!r} leaves the output directory ('..')"
    return None


def resolve_output(out_dir: str | os.PathLike[str], relpath: str) -> Path:
    """The absolute path of ``relpath`` inside ``out_dir``, refusing any escape.

    Raises
    ------
    PathError
        For absolute paths, ``..``, and symlinks (of folders or of the file) leading out.
    """
    problem = path_problem(relpath)
    if problem:
        raise PathError(problem)
    root = Path(out_dir).resolve()
    target = root / PurePosixPath(relpath.replace("\\", "/"))
    real = target.resolve()  # follows any symlinks that exist along the way
    if real != root and root not in real.parents:
        raise PathError(
            f"output path {relpath!r} leads outside the output directory {str(root)!r} "
            f"(through a symlink)"
        )
    if real == root:
        raise PathError(f"output path {relpath!r} names the output directory itself")
    return real


def write_atomic(out_dir: str | os.PathLike[str], relpath: str, data: bytes | memoryview) -> Path:
    """Write ``data`` to ``relpath`` inside ``out_dir``, atomically; returns the path.

    Creates sub-folders; leaves an existing file untouched when it already holds ``data``.
    On any failure the previous file (if any) is intact and no temp file is left behind.
    ``data`` is any bytes-like object; it is written as it is, never copied.
    """
    data = memoryview(data).cast("B")
    target = resolve_output(out_dir, relpath)
    target.parent.mkdir(parents=True, exist_ok=True)
    target = resolve_output(out_dir, relpath)  # a folder made meanwhile could be a symlink
    try:
        if target.is_file() and target.stat().st_size == data.nbytes and _holds(target, data):
            return target
    except OSError:
        pass
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return target


def _holds(path: Path, data: memoryview, chunk: int = 1 << 20) -> bool:
    """Whether the file holds exactly ``data`` (of its size), read a chunk at a time (a big
    export is not read into a second buffer of its size)."""
    buffer = bytearray(min(chunk, max(len(data), 1)))
    view = memoryview(buffer)
    with open(path, "rb") as fh:
        for start in range(0, len(data), len(buffer)):
            got = fh.readinto(buffer)
            if got == 0 or view[:got] != data[start : start + got]:
                return False
    return True
