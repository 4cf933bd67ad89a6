"""SIGINT/SIGTERM handling for the executables, installed before anything heavy is imported.

The handlers only record the request; the main thread waits on it (an interruptible wait, so
the handlers run at once) and then shuts the process down in order. Installed first thing in
the entry points, a signal during start-up ends the process cleanly instead of raising
``KeyboardInterrupt`` in the middle of an import.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType
from typing import Any

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopSignal:
    """Records SIGINT/SIGTERM while installed (a context manager)."""

    def __init__(self) -> None:
        self._requested = threading.Event()
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> StopSignal:
        for sig in SIGNALS:
            self._previous[sig] = signal.signal(sig, self._request)
        # SIGUSR1 asks a running bridge for its status table; until the table handler is
        # installed it must not terminate the process (its default action).
        if signal.getsignal(signal.SIGUSR1) == signal.SIG_DFL:
            self._previous[signal.SIGUSR1] = signal.signal(signal.SIGUSR1, signal.SIG_IGN)
        return self

    def __exit__(self, *_exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()

    def _request(self, _signum: int, _frame: FrameType | None) -> None:
        self._requested.set()

    @property
    def requested(self) -> bool:
        return self._requested.is_set()

    def wait(self, timeout: float) -> bool:
        """Wait up to ``timeout`` seconds for a stop request; True once one arrived."""
        return self._requested.wait(timeout)
