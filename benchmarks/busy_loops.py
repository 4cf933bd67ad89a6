"""Busy loops beside a measurement, as on a user's machine where something else runs."""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def busy_loops(count: int) -> Iterator[None]:
    """``count`` processes at 100% of a core each (``yes``) while the block runs. Each is in a
    process group of its own, killed whole (``timeout`` and ``yes``) when the block ends; they
    stop by themselves after 15 minutes if this process dies first."""
    loops = [
        subprocess.Popen(
            ["timeout", "900", "yes"], stdout=subprocess.DEVNULL, start_new_session=True
        )
        for _ in range(count)
    ]
    try:
        yield
    finally:
        for loop in loops:
            os.killpg(loop.pid, signal.SIGKILL)
            loop.wait()
