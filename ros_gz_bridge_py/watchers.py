"""Callbacks to tell when something changed, for loops that do not ask at every turn.

Watchers are added and removed from any thread (under a lock) and called on the thread that made
the change, each call on the set of the moment. A watcher must be quick and must not raise.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class Watchers:
    """The callbacks watching one thing."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._callbacks: tuple[Callable[[], None], ...] = ()

    def add(self, changed: Callable[[], None]) -> Callable[[], None]:
        """Call ``changed()`` at each :meth:`notify`; returns the function that stops it."""
        with self._lock:
            self._callbacks = (*self._callbacks, changed)

        def remove() -> None:
            with self._lock:
                self._callbacks = tuple(c for c in self._callbacks if c is not changed)

        return remove

    def notify(self) -> None:
        """Call every watcher (outside the lock: one may add or remove)."""
        for changed in self._callbacks:
            changed()
