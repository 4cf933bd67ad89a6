"""batch_dds_event_threads: which threads it puts under SCHED_BATCH, and what it skips."""

from __future__ import annotations

import os
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.ros.runtime import batch_dds_event_threads, steady_clock


@pytest.fixture
def waiting_thread() -> Iterator[int]:
    """The native id of a thread that waits until the test ends (its policy dies with it)."""
    started, release = threading.Event(), threading.Event()
    ids: list[int] = []

    def wait() -> None:
        ids.append(threading.get_native_id())
        started.set()
        release.wait()

    thread = threading.Thread(target=wait, daemon=True)
    thread.start()
    started.wait()
    yield ids[0]
    release.set()
    thread.join()


def task(tasks: Path, name: str, comm: str) -> None:
    (tasks / name).mkdir()
    (tasks / name / "comm").write_text(comm + "\n")


def test_a_dds_event_thread_is_batched_and_nothing_else(
    tmp_path: Path, waiting_thread: int
) -> None:
    task(tmp_path, str(waiting_thread), "dds.ev.0")
    task(tmp_path, str(os.getpid()), "python")  # another name: left alone
    task(tmp_path, "not-a-number", "dds.ev.1")  # unusable: skipped without a word
    (tmp_path / "9").mkdir()  # a thread gone before its name was read
    assert os.sched_getscheduler(waiting_thread) == os.SCHED_OTHER
    assert batch_dds_event_threads(tmp_path) == 1
    assert os.sched_getscheduler(waiting_thread) == os.SCHED_BATCH
    assert os.sched_getscheduler(os.getpid()) == os.SCHED_OTHER


def test_no_such_threads_changes_nothing(tmp_path: Path) -> None:
    task(tmp_path, str(os.getpid()), "python")
    assert batch_dds_event_threads(tmp_path) == 0
    assert batch_dds_event_threads(tmp_path / "absent") == 0
    assert os.sched_getscheduler(os.getpid()) == os.SCHED_OTHER


def test_the_bridges_timers_share_one_steady_clock() -> None:
    """The EventsExecutor keeps a thread for each clock object its timers use: every timer of
    the bridge's node (heartbeat, explanations, discovered bridging, /diagnostics) takes this
    one, so turning those on adds no thread (issue 28: no more threads than the C++ bridge)."""
    from rclpy.clock import ClockType  # noqa: PLC0415 - rclpy only for the tests that use it

    assert steady_clock() is steady_clock()
    assert steady_clock().clock_type == ClockType.STEADY_TIME
