"""How many bytes this process may still take: the room a node's output must fit in.

The element budget bounds what a node makes, not what the machine holds: one in-budget
grid of 45 million points is a gigabyte, and a run holds every node's output until it
ends. So a node that declares the bytes it would make (``ctx.guard(..., nbytes=...)``) is
also refused, before it allocates, when those bytes and one transient copy of them (a
value is frozen into an immutable buffer once made) do not fit in what the process has
left: the least of

- its address-space limit (``RLIMIT_AS``, as ``ulimit -v`` or a job scheduler sets it)
  less the address space it already maps (``VmSize``: what that limit counts);
- its control group's memory limit (a container's: ``memory.max`` of cgroup v2,
  ``memory.limit_in_bytes`` of v1) less what the group already uses;
- the memory the machine still has for new allocations (``MemAvailable``).

Where the operating system does not say (no ``/proc``), only ``RLIMIT_AS`` is known, and
without one nothing is refused here: the element budget still is.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

__all__ = ["PEAK_FACTOR", "UNCHECKED", "Room", "fmt_bytes", "room"]

PEAK_FACTOR = 2
"""What making an output of n bytes takes at its peak: the output, and the one copy of it
that freezing it into an immutable buffer makes (every node's peak is held to this)."""


UNCHECKED = 1 << 24
"""Needs below this many bytes are not checked: reading the limits (three small files)
costs more than so little could matter, and a repeat may make thousands of small outputs."""


@dataclass(frozen=True)
class Room:
    """The bytes the process may still take, and the limit that says so."""

    bytes: int
    limit: int  # the limit itself
    used: int  # what counts against it already
    what: str  # "the address-space limit (RLIMIT_AS)", ...

    def describe(self) -> str:
        return (
            f"{fmt_bytes(max(self.bytes, 0))} left under {self.what} of {fmt_bytes(self.limit)} "
            f"({fmt_bytes(self.used)} in use)"
        )


def room() -> Room | None:
    """The tightest of the limits the process runs under (see the module's docstring), or
    None when none is known."""
    found = [r for r in (_address_space(), _cgroup(), _available()) if r is not None]
    return min(found, key=lambda r: r.bytes) if found else None


def _address_space() -> Room | None:
    try:
        import resource
    except ImportError:  # not on this platform
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY or soft <= 0:
        return None
    mapped = _statm(0)
    if mapped is None:  # what counts against it is unknown: the whole limit, less nothing
        mapped = 0
    return Room(soft - mapped, soft, mapped, "the address-space limit (RLIMIT_AS)")


def _cgroup() -> Room | None:
    try:
        text = Path("/proc/self/cgroup").read_text()
    except OSError:
        return None
    for line in text.splitlines():
        _, controllers, path = line.split(":", 2) if line.count(":") >= 2 else ("", "", "")
        path = path.strip().lstrip("/")
        if controllers == "" and line.startswith("0::"):  # cgroup v2: one hierarchy
            files = ("memory.max", "memory.current")
            folders = [Path("/sys/fs/cgroup") / path, Path("/sys/fs/cgroup")]
        elif "memory" in controllers.split(","):  # cgroup v1: the memory controller's
            files = ("memory.limit_in_bytes", "memory.usage_in_bytes")
            base = Path("/sys/fs/cgroup/memory")
            folders = [base / path, base]  # inside a container, its own group is the root
        else:
            continue
        for folder in folders:
            try:
                limit = (folder / files[0]).read_text().strip()
                used = int((folder / files[1]).read_text().strip())
            except (OSError, ValueError):
                continue
            if not limit.isdigit() or int(limit) >= 1 << 60:  # "max", or v1's "no limit"
                break
            return Room(int(limit) - used, int(limit), used, f"the control group's {files[0]}")
    return None


def _available() -> Room | None:
    try:
        text = Path("/proc/meminfo").read_text()
    except OSError:
        return None
    fields = {}
    for line in text.splitlines():
        name, _, rest = line.partition(":")
        parts = rest.split()
        if parts and parts[0].isdigit():
            fields[name] = int(parts[0]) * 1024  # kB
    if "MemAvailable" not in fields or "MemTotal" not in fields:
        return None
    total, free = fields["MemTotal"], fields["MemAvailable"]
    return Room(free, total, total - free, "the machine's memory")


def _statm(field: int) -> int | None:
    """A field of ``/proc/self/statm`` in bytes (0: address space mapped, 1: resident)."""
    try:
        values = Path("/proc/self/statm").read_text().split()
        return int(values[field]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


def fmt_bytes(n: float) -> str:
    """Bytes for a message: ``1.08 GB``, ``640 MB``, ``12 kB``, ``512 bytes`` (powers of
    1000, as people and ``ls -lh --si`` read them)."""
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if abs(n) >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} bytes"


def ran_out(exc: MemoryError) -> str:
    """The message for a node that ran out of memory without saying beforehand what it would
    take (nothing refused it): numpy's own words, and what the process has left now."""
    left = room()
    said = f"ran out of memory ({exc or 'MemoryError'})"
    return said + (f"; the process has {left.describe()}" if left is not None else "")
