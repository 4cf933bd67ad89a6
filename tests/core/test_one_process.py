"""The package's own rule: starting a process from a core test is refused and fails it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.core.one_process import SubprocessStartedError, child_processes


def test_starting_a_process_is_refused_and_recorded(refused_processes: list[str]) -> None:
    before = len(refused_processes)
    with pytest.raises(SubprocessStartedError):
        subprocess.run([sys.executable, "-c", "pass"], check=False)
    with pytest.raises(SubprocessStartedError):
        os.system("true")  # noqa: S605 - the call under test is the refusal itself
    with pytest.raises(SubprocessStartedError):
        os.fork()
    assert refused_processes[before:] == ["_execute_child", "system", "fork"]
    # Forget them again: this test meant to try (the one_process fixture fails the others).
    del refused_processes[before:]
    assert child_processes() == []
