"""A status line on a terminal: rewritten in place, rate-limited, silent on pipes and files."""

from __future__ import annotations

import time
from typing import Any

__all__ = ["StatusLine"]


class StatusLine:
    """One line of status (``\\r`` + erase + text) that only a terminal gets.

    Parameters
    ----------
    stream : text stream
        Written only when ``stream.isatty()``.
    quiet_for : float
        Seconds after creation during which nothing is shown (quick runs stay silent).
    interval : float
        Least seconds between two updates (a write per event would cost more than the
        events themselves).
    """

    def __init__(self, stream: Any, *, quiet_for: float = 0.0, interval: float = 0.05):
        self.stream = stream
        self.enabled = hasattr(stream, "isatty") and stream.isatty()
        self.quiet_for = quiet_for
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -float("inf")
        self.shown = False

    def show(self, text: str, *, force: bool = False) -> None:
        """Replace the line with ``text``, unless too soon (``force`` skips the limits)."""
        if not self.enabled:
            return
        now = time.perf_counter()
        if not force and (now - self.start < self.quiet_for or now - self.last < self.interval):
            return
        self.last = now
        self.stream.write("\r\x1b[K" + text)
        self.stream.flush()
        self.shown = True

    def clear(self) -> None:
        """Erase the line, if one was shown."""
        if self.shown:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
