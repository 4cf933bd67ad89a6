"""Real publishers (or echoes) run a few at a time, for the wire tests."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Sequence
from typing import Any

#: Publishing processes alive at once (the machine has 2 cores).
PARALLEL = 4
#: How long one publisher may take to deliver before it is retried or given up.
DELIVERY_TIMEOUT = 15.0


def run_limited(jobs: Sequence[Any], parallel: int) -> None:
    """Run ``jobs`` (``start()``, ``step() -> finished``) with at most ``parallel`` alive."""
    waiting = deque(jobs)
    running: list[Any] = []
    while waiting or running:
        while waiting and len(running) < parallel:
            job = waiting.popleft()
            job.start()
            running.append(job)
        running = [job for job in running if not job.step()]
        time.sleep(0.02)
