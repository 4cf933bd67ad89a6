"""At most one warning per period: a flood of bad input is counted in full, logged rarely."""

from __future__ import annotations

import time
from collections.abc import Hashable


class Throttle:
    """Says yes at most once per ``period`` seconds for each key (not thread-safe: callers
    that share one hold their own lock)."""

    def __init__(self, period: float) -> None:
        self.period = period
        self._last: dict[Hashable, float] = {}

    def ready(self, key: Hashable = None) -> bool:
        """True (and the period starts again) when ``key`` was last ready a period ago."""
        now = time.monotonic()
        last = self._last.get(key)
        if last is not None and now - last < self.period:
            return False
        self._last[key] = now
        return True
