"""The demo's child processes: started with their output in a log file, stopped for sure.

Each child gets a session of its own, so a Ctrl-C in the terminal reaches only the demo, which
then stops the children in order (SIGTERM to the child's process group, SIGKILL after a grace
period). The kernel also sends SIGTERM to a child whose parent dies (``PR_SET_PDEATHSIG``),
so even a killed demo leaves nothing behind.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ros_gz_bridge_py.libc import libc_function

PR_SET_PDEATHSIG = 1
GRACE_SECONDS = 5.0


def _die_with_parent() -> None:
    """Runs in the child between fork and exec."""
    prctl = libc_function("prctl")
    if prctl is not None:
        prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


class Child:
    """One started process and the file its stdout and stderr go to."""

    def __init__(
        self, name: str, command: Sequence[str], log_path: Path, env: Mapping[str, str]
    ) -> None:
        """Start ``command`` with our environment plus ``env``."""
        self.name = name
        self.command = list(command)
        self.log_path = log_path
        with log_path.open("wb") as log:
            self.process = subprocess.Popen(
                self.command,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                env={**os.environ, **env},
                start_new_session=True,
                preexec_fn=_die_with_parent,  # noqa: PLW1509 - no threads exist yet
            )

    @property
    def pid(self) -> int:
        return self.process.pid

    def exited(self) -> int | None:
        """The exit status once the process has ended, else None."""
        return self.process.poll()

    def log(self) -> str:
        return self.log_path.read_text(errors="replace")

    def wait_for_output(self, text: str, timeout: float, give_up: Callable[[], bool]) -> bool:
        """Whether ``text`` appears in the log within ``timeout`` seconds while it runs.

        Stops waiting early when the process ends or ``give_up()`` is true.
        """
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.exited() is None and not give_up():
            if text in self.log():
                return True
            time.sleep(0.1)
        return text in self.log()

    def stop(self, grace: float = GRACE_SECONDS) -> None:
        """SIGTERM the process group, SIGKILL it after ``grace`` seconds; reaps the child.

        Signals go only while the child is unreaped, so its group id cannot have been reused.
        """
        if self.exited() is not None:
            return
        self._signal_group(signal.SIGTERM)
        try:
            self.process.wait(grace)
        except subprocess.TimeoutExpired:
            self._signal_group(signal.SIGKILL)
            self.process.wait()

    def _signal_group(self, sig: signal.Signals) -> None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.pid, sig)
