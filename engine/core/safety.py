"""Reading and writing files safely: regular files only, atomically, inside their folder.

Every file formgraph reads (graphs, subgraph parts, the inputs of read nodes) goes through
:func:`read_regular`: a FIFO, a device or a socket named as a graph would block ``open`` or
``read`` forever, so the file is opened without blocking and refused unless it is a regular
file, and never read past its size limit.

A graph downloaded from someone else must not write anywhere but the output directory, so
every export path is relative, free of ``..``, and still inside the directory after symlinks
are followed. Files appear whole or not at all (temp file in the same folder, fsync,
``os.replace``), and a file that already holds exactly the bytes is left untouched. A temp
file names the process that writes it, so one left behind by a killed run is removed by the
next write into its folder.

Inputs (the files ``read.*`` nodes read) follow the export paths' rules inside the inputs
folder (the graph's folder unless the run names one): :func:`resolve_input`, then
:func:`read_input`, under :data:`MAX_INPUT_BYTES`.
"""

from __future__ import annotations

import errno
import io
import os
import re
import stat
import tempfile
import time
from collections.abc import Iterable
from pathlib import Path, PurePosixPath, PureWindowsPath

from ..kernels.buffers import filled_bytes
from .errors import PathError

MAX_PATH_CHARS = 1024
MAX_PATH_PARTS = 32  # folders deep
MAX_NAME_CHARS = 200  # per folder or file name, leaving room for the temp file's affixes
TMP_TAG = ".fgtmp-"  # temp files are '.{name}.fgtmp-{pid}-{random}.tmp'
_TMP = re.compile(r"^\..+\.fgtmp-(\d+)-[^.]+\.tmp$")
STALE_SECONDS = 24 * 3600  # a temp file this old is stale whoever wrote it


MAX_INPUT_BYTES = 1 << 30  # the largest input file a read node opens


def path_problem(
    relpath: str,
    what: str = "output path",
    root: str = "the output directory",
    *,
    output: bool = True,
) -> str | None:
    """Why ``relpath`` may not be an output path, or None when it may (no file access).

    ``what`` and ``root`` name the path and its folder in the message (``"input path"``,
    ``"the inputs folder"`` for the files a graph reads, with ``output=False``). Every
    export's path is checked here, at load and again when it writes: a path must name a
    file (not end in ``/`` or ``.``: ``sub/`` would write a file called ``sub``), and an
    output may not be named like our temp files (``.NAME.fgtmp-PID-*.tmp``), which the next
    write into its folder deletes once that process is gone.
    """
    if not isinstance(relpath, str) or not relpath.strip():
        return f"an {what} must be a non-empty relative path"
    if "\x00" in relpath:
        return f"an {what} must not contain NUL characters"
    posix, win = PurePosixPath(relpath), PureWindowsPath(relpath)
    if (
        posix.is_absolute()
        or win.is_absolute()
        or win.drive
        or relpath.startswith(("/", "\\", "~"))
    ):
        return f"{what} {relpath!r} is absolute; give a path relative to {root}"
    if ".." in posix.parts or ".." in win.parts:
        return f"{what} {relpath!r} leaves {root} ('..')"
    shown = relpath if len(relpath) <= 60 else relpath[:57] + "..."
    if len(relpath) > MAX_PATH_CHARS:
        return f"{what} {shown!r} is {len(relpath):,} characters long (at most {MAX_PATH_CHARS})"
    parts = [p for p in relpath.replace("\\", "/").split("/") if p not in ("", ".")]
    if len(parts) > MAX_PATH_PARTS:
        return f"{what} {shown!r} is {len(parts):,} folders deep (at most {MAX_PATH_PARTS})"
    if any(len(p) > MAX_NAME_CHARS for p in parts):
        return f"{what} {shown!r} has a name longer than {MAX_NAME_CHARS} characters"
    last = re.split(r"[/\\]", relpath)[-1]
    if last in ("", "."):
        return f"{what} {shown!r} names a folder, not a file; give the file's name after it"
    if output and _TMP.match(last):
        return (
            f"{what} {shown!r} is named like formgraph's temporary files "
            "('.NAME.fgtmp-PID-*.tmp'), which the next write into its folder deletes; "
            "choose another name"
        )
    return None


def output_root(out_dir: str | os.PathLike[str]) -> Path:
    """The output directory, absolute, symlinks followed (it need not exist yet).

    Raises
    ------
    PathError
        When it cannot be followed (a symlink loop) or is something other than a folder.
    """
    try:
        root = Path(out_dir).resolve()
    except (OSError, RuntimeError) as exc:  # RuntimeError: a symlink loop (Python < 3.13)
        raise PathError(
            f"the output directory {str(out_dir)!r} cannot be followed: {exc}"
        ) from None
    if root.exists() and not root.is_dir():
        raise PathError(f"the output directory {str(out_dir)!r} is not a folder")
    return root


def resolve_output(out_dir: str | os.PathLike[str], relpath: str) -> Path:
    """The absolute path of ``relpath`` inside ``out_dir``, refusing any escape.

    Raises
    ------
    PathError
        For absolute paths, ``..``, and symlinks (of folders or of the file) leading out.
    """
    root = output_root(out_dir)
    return _inside(root, relpath, "output path", "the output directory", output=True)


def resolve_input(
    root: str | os.PathLike[str], relpath: str, base: str | os.PathLike[str] | None = None
) -> Path:
    """The absolute path of the input ``relpath`` (relative to ``base``, default ``root``),
    refusing any escape from ``root`` by the rules of :func:`resolve_output`.

    Raises
    ------
    PathError
        For absolute paths, ``..``, a symlink leading out of ``root``, or a root that
        cannot be followed.
    """
    where = "the inputs folder"
    top = _root(root, "inputs folder")
    if base is None:
        return _inside(top, relpath, "input path", where, output=False)
    real = _inside(_root(base, "inputs folder"), relpath, "input path", where, output=False)
    if real != top and top not in real.parents:
        raise PathError(
            f"input path {relpath!r} leads outside the inputs folder {str(top)!r} (through a "
            f"symlink)"
        )
    return real


def _root(folder: str | os.PathLike[str], what: str) -> Path:
    try:
        return Path(folder).resolve()
    except (OSError, RuntimeError) as exc:  # RuntimeError: a symlink loop (Python < 3.13)
        raise PathError(f"the {what} {str(folder)!r} cannot be followed: {exc}") from None


def _inside(root: Path, relpath: str, what: str, where: str, *, output: bool) -> Path:
    problem = path_problem(relpath, what, where, output=output)
    if problem:
        raise PathError.of(relpath, problem)
    try:
        target = root / PurePosixPath(relpath.replace("\\", "/"))
        real = target.resolve()  # follows any symlinks that exist along the way
    except (OSError, RuntimeError) as exc:  # RuntimeError: a symlink loop (Python < 3.13)
        raise PathError.of(relpath, f"{what} {relpath!r} cannot be followed: {exc}") from None
    if real != root and root not in real.parents:
        raise PathError.of(
            relpath, f"{what} {relpath!r} leads outside {where} {str(root)!r} (through a symlink)"
        )
    if real == root:
        raise PathError.of(relpath, f"{what} {relpath!r} names {where} itself")
    return real


def write_atomic(
    out_dir: str | os.PathLike[str],
    relpath: str,
    data: bytes | memoryview | Iterable[bytes | memoryview],
) -> Path:
    """Write ``data`` to ``relpath`` inside ``out_dir``, atomically; returns the path.

    Creates sub-folders; leaves an existing file untouched when it already holds ``data``.
    On any failure the previous file (if any) is intact and no temp file is left behind.
    ``data`` is any bytes-like object, written as it is, never copied; or an iterable of
    them (pieces of a big file made one after another, each written before the next is
    made: the whole file is never in memory), compared with an existing file only once
    written to the temp file.
    """
    pieces = None
    try:
        data = memoryview(data).cast("B")
    except TypeError:  # not bytes-like: an iterable of pieces
        pieces = iter(data)
    target = resolve_output(out_dir, relpath)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise PathError.of(
            relpath, f"output path {relpath!r} runs through a file, not a folder"
        ) from None
    target = resolve_output(out_dir, relpath)  # a folder made meanwhile could be a symlink
    if pieces is None:
        try:
            if target.is_file() and target.stat().st_size == data.nbytes and _holds(target, data):
                return target
        except OSError:
            pass
    remove_stale_temps(target.parent)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.name}{TMP_TAG}{os.getpid()}-", suffix=".tmp", dir=target.parent
    )
    try:
        with os.fdopen(fd, "wb") as fh:
            if pieces is None:
                fh.write(data)
            else:
                for piece in pieces:
                    fh.write(piece)
            fh.flush()
            os.fsync(fh.fileno())
        if pieces is not None and _same_file(target, Path(tmp)):
            os.unlink(tmp)
            return target
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return target


def _same_file(target: Path, tmp: Path, chunk: int = 1 << 20) -> bool:
    """Whether ``target`` is a regular file with exactly the bytes of ``tmp`` (read a chunk
    at a time)."""
    try:
        if not target.is_file() or target.stat().st_size != tmp.stat().st_size:
            return False
        with open(target, "rb") as a, open(tmp, "rb") as b:
            while True:
                x, y = a.read(chunk), b.read(chunk)
                if x != y:
                    return False
                if not x:
                    return True
    except OSError:
        return False


_KINDS = {
    stat.S_IFIFO: "a FIFO (named pipe)",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
    stat.S_IFDIR: "a folder",
}


def read_regular(path: str | os.PathLike[str], *, max_bytes: int) -> bytes:
    """The bytes of a regular file, at most ``max_bytes`` of them.

    Opened with ``O_NONBLOCK`` (a FIFO's ``open`` returns at once instead of waiting for a
    writer) and checked with ``fstat`` on the open descriptor, so what is read is what was
    checked.

    Raises
    ------
    OSError
        The file cannot be opened; it is not a regular file (``errno.EINVAL``, "is a FIFO
        (named pipe), not a regular file"); it is larger than ``max_bytes``
        (``errno.EFBIG``, "is larger than 16 MiB").
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a file")
            raise OSError(errno.EINVAL, f"it is {kind}, not a regular file", str(path))
        if st.st_size > max_bytes:
            raise OSError(errno.EFBIG, f"it is larger than {_size(max_bytes)}", str(path))
        # the size fstat gave, read straight into the bytes returned (one buffer, no
        # chunks joined: the file's size in memory, not twice it)
        data = filled_bytes(st.st_size, lambda view: _read_into(fd, view))
        chunks, total = [data], len(data)
        while total <= max_bytes:  # the file may grow while it is read
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > max_bytes:
            raise OSError(errno.EFBIG, f"it is larger than {_size(max_bytes)}", str(path))
        return data if len(chunks) == 1 else b"".join(chunks)
    finally:
        os.close(fd)


def _read_into(fd: int, view: memoryview) -> int:
    """Fill ``view`` from ``fd`` (short reads continued); the bytes read (fewer at the
    end of a file that shrank)."""
    total = 0
    with io.FileIO(fd, closefd=False) as f:
        while total < len(view):
            n = f.readinto(view[total:])
            if not n:
                break
            total += n
    return total


def _size(n: int) -> str:
    return f"{n // (1 << 20)} MiB" if n >= 1 << 20 and n % (1 << 20) == 0 else f"{n:,} bytes"


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


def remove_stale_temps(folder: Path) -> list[Path]:
    """Delete the temp files of ours in ``folder`` that no running writer owns; returns them.

    A temp file is stale when the process named in it is gone (a run killed mid-write), or
    when it is older than a day (a writer on another machine sharing the folder).
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    now = time.time()
    for entry in entries:
        m = _TMP.match(entry.name)
        if m is None:
            continue
        try:
            stale = not _running(int(m.group(1))) or now - entry.stat().st_mtime > STALE_SECONDS
            if stale and entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            continue  # another writer removed or replaced it meanwhile
    return removed


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True  # someone else's process, or a number we cannot ask about: keep it
    return True


def read_input(path: str | os.PathLike[str], max_bytes: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of an input file (:func:`read_regular`), its refusal a :class:`PathError`
    saying why in a sentence ("does not exist", "is a FIFO (named pipe), not a regular file",
    "is larger than 1024 MiB")."""
    try:
        return read_regular(path, max_bytes=max_bytes)
    except FileNotFoundError:
        raise PathError(f"{os.fspath(path)!r} does not exist") from None
    except OSError as exc:
        why = exc.strerror or str(exc)
        why = why[3:] if why.startswith("it ") else why
        raise PathError(f"{os.fspath(path)!r} {why}") from None
