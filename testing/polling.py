"""Polling for in-process tests: wait for a condition, and let the test assert on the outcome."""

from __future__ import annotations

import time
from collections.abc import Callable

#: Seconds a condition may take to come true.
LIMIT = 10.0


def wait_until(condition: Callable[[], bool], timeout: float = LIMIT) -> bool:
    """Poll ``condition`` every 10 ms until it is true (True) or ``timeout`` seconds have
    passed (False); tests assert on the outcome, never on the time taken."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True
