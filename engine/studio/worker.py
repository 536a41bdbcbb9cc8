"""One thread that does the studio's engine work, newest request first.

The page's event loop must stay free to answer the browser, so every request to the
:class:`~.session.StudioSession` (a slider step, an edit, a click, Save, Run) runs here, one
at a time. Requests come in kinds; a request replaces one of the same kind still waiting,
and one of the same kind still running is stopped between two of its nodes (the session's
progress hook raises :class:`~.session.Superseded`), so dragging a slider never builds a
queue of stale recooks: the picture follows the newest value.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from .session import Superseded

__all__ = ["Worker"]


class Worker:
    """Runs ``fn(*args)`` requests in a thread and hands each result to ``deliver``.

    Parameters
    ----------
    deliver : callable
        ``deliver(kind, result, seconds)``, called in the worker thread after each request
        that ran to its end (a superseded one delivers nothing); it must hand the result on
        to the thread that owns the page.
    on_error : callable
        ``on_error(kind, exc)`` for an exception a request raised (a bug of ours: the
        studio must keep running).
    """

    def __init__(
        self,
        deliver: Callable[[str, Any, float], None],
        on_error: Callable[[str, BaseException], None],
    ):
        self.deliver = deliver
        self.on_error = on_error
        self._cv = threading.Condition()
        self._pending: dict[str, tuple[Callable[..., Any], tuple[Any, ...], float]] = {}
        self._running: str | None = None
        self._stopped = False
        self.superseded = 0  # requests stopped or replaced by newer ones
        self.done = 0
        self._thread = threading.Thread(target=self._loop, name="formgraph-studio", daemon=True)
        self._thread.start()

    def submit(self, kind: str, fn: Callable[..., Any], *args: Any) -> None:
        """Ask for ``fn(*args)``; an older request of ``kind`` not yet finished is dropped."""
        with self._cv:
            if self._pending.pop(kind, None) is not None:
                self.superseded += 1
            self._pending[kind] = (fn, args, time.perf_counter())
            self._cv.notify()

    def check(self, *_: Any) -> None:
        """The progress hook: stop the running request if a newer one of its kind waits."""
        if self._running is not None and self._running in self._pending:
            raise Superseded(self._running)

    def waiting(self, kind: str) -> bool:
        """Whether a request of ``kind`` waits to run."""
        with self._cv:
            return kind in self._pending

    def idle(self, ignore: tuple[str, ...] = ()) -> bool:
        """Whether nothing runs or waits, requests of the kinds in ``ignore`` aside."""
        with self._cv:
            running = self._running is not None and self._running not in ignore
            return not running and all(kind in ignore for kind in self._pending)

    def stop(self) -> None:
        with self._cv:
            self._stopped = True
            self._pending.clear()
            self._cv.notify()

    def _loop(self) -> None:
        while True:
            with self._cv:
                while not self._pending and not self._stopped:
                    self._cv.wait()
                if self._stopped:
                    return
                kind = next(iter(self._pending))
                fn, args, asked = self._pending.pop(kind)
                self._running = kind
            try:
                result = fn(*args)
            except Superseded:
                self.superseded += 1
                continue
            except Exception as exc:  # a bug of ours must not end the studio
                self.on_error(kind, exc)
                continue
            finally:
                with self._cv:
                    self._running = None
            self.done += 1
            self.deliver(kind, result, time.perf_counter() - asked)
