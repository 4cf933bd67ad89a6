"""batch_dds_event_threads: which threads it puts under SCHED_BATCH, and what it skips;
SignalWake: a signal ends a spin step."""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.ros.runtime import SignalWake, batch_dds_event_threads


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


@pytest.mark.ros
@pytest.mark.parametrize("events", [True, False], ids=["EventsExecutor", "single"])
def test_a_signal_ends_a_spin_step_at_once(ros_context: Any, events: bool) -> None:
    """The bridge spins in long steps; a signal (here SIGUSR2, as SIGINT would) ends the step
    it arrives in and its Python handler runs right after, on the main thread."""
    import rclpy  # noqa: PLC0415 - only the tests that ask for a context load it
    from rclpy.executors import SingleThreadedExecutor  # noqa: PLC0415
    from rclpy.experimental import EventsExecutor  # noqa: PLC0415

    node = rclpy.create_node("signal_wake_test", context=ros_context)
    kind = EventsExecutor if events else SingleThreadedExecutor
    executor = kind(context=ros_context)
    executor.add_node(node)
    handled: list[str] = []
    previous = signal.signal(
        signal.SIGUSR2, lambda *_: handled.append(threading.current_thread().name)
    )
    try:
        with SignalWake(node):
            for _ in range(2):  # the wake is ready again after it fired
                threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGUSR2)).start()
                started = time.monotonic()
                executor.spin_once(timeout_sec=60)
                assert time.monotonic() - started < 30, "the signal did not end the step"
                executor.spin_once(timeout_sec=0)  # the handler runs between steps
        assert handled == ["MainThread", "MainThread"]
        assert not any(t.name == "signal-wake" for t in threading.enumerate())
    finally:
        signal.signal(signal.SIGUSR2, previous)
        executor.shutdown()
        node.destroy_node()
