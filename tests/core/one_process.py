"""The rule of tests/core: everything runs in the pytest process, nothing starts another.

:func:`refusing_processes` replaces every way Python has to start a process
(``subprocess.Popen``, ``os.fork``, ``os.posix_spawn``, ``os.system``, ...) by a refusal that
raises :class:`SubprocessStartedError` and records the attempt; ``conftest.py`` keeps it on
while the package runs and fails each test that tried, or that left a child process.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

#: The functions that start processes, by owner; each is replaced by a refusal.
PROCESS_STARTERS: dict[Any, tuple[str, ...]] = {
    subprocess.Popen: ("_execute_child",),
    os: ("fork", "forkpty", "posix_spawn", "posix_spawnp", "system"),
}


class SubprocessStartedError(AssertionError):
    """A test of tests/core tried to start a process."""


def _refusal(name: str, attempts: list[str]) -> Callable[..., Any]:
    def refuse(*_args: Any, **_kwargs: Any) -> Any:
        attempts.append(name)
        msg = f"tests/core runs in one process; {name} was called"
        raise SubprocessStartedError(msg)

    return refuse


@contextmanager
def refusing_processes() -> Iterator[list[str]]:
    """While inside, starting a process raises; yields the names of what was attempted."""
    attempts: list[str] = []
    with pytest.MonkeyPatch.context() as patch:
        for owner, names in PROCESS_STARTERS.items():
            for name in names:
                if hasattr(owner, name):
                    patch.setattr(owner, name, _refusal(name, attempts))
        yield attempts


def child_processes() -> list[int]:
    """The process ids of this process's children (Linux; [] where /proc cannot tell)."""
    children: list[int] = []
    for task in Path("/proc/self/task").glob("*/children"):
        try:
            children += [int(pid) for pid in task.read_text().split()]
        except OSError:
            continue
    return children
