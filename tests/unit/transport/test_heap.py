"""Trimming the heap after a burst of large messages, never during a steady stream."""

from __future__ import annotations

from ros_gz_bridge_py.transport.heap import (
    IDLE_BEFORE_TRIM,
    TRIM_AFTER_BYTES,
    BurstTrimmer,
    trim_heap,
)


def test_a_burst_is_trimmed_once_it_is_over() -> None:
    trims: list[int] = []
    trimmer = BurstTrimmer(lambda: trims.append(1))
    trimmer.received(TRIM_AFTER_BYTES)
    now = trimmer._last
    trimmer.idle(now + IDLE_BEFORE_TRIM / 2)  # still in the burst
    assert trims == []
    trimmer.idle(now + IDLE_BEFORE_TRIM)
    assert trims == [1]
    trimmer.idle(now + 10 * IDLE_BEFORE_TRIM)  # nothing new since
    assert trimmer.trims == 1


def test_small_traffic_is_never_trimmed() -> None:
    trimmer = BurstTrimmer(lambda: None)
    trimmer.received(TRIM_AFTER_BYTES - 1)
    trimmer.idle(trimmer._last + 100)
    assert trimmer.trims == 0


def test_trim_heap_runs_here() -> None:
    assert isinstance(trim_heap(), bool)  # glibc: malloc_trim(0); elsewhere a no-op


def test_running_totals_trim_once_a_burst_has_stopped_growing() -> None:
    """The native loop's form: each count gives the bytes read so far."""
    trimmer = BurstTrimmer(lambda: None)
    trimmer.read_so_far(TRIM_AFTER_BYTES // 2, 10.0)
    trimmer.read_so_far(TRIM_AFTER_BYTES, 10.5)
    trimmer.read_so_far(TRIM_AFTER_BYTES, 10.5 + IDLE_BEFORE_TRIM / 2)  # a short pause
    assert trimmer.trims == 0
    trimmer.read_so_far(TRIM_AFTER_BYTES, 10.5 + IDLE_BEFORE_TRIM)
    assert trimmer.trims == 1
    trimmer.read_so_far(TRIM_AFTER_BYTES + 1, 20.0)  # a trickle afterwards: no new burst
    trimmer.read_so_far(TRIM_AFTER_BYTES + 1, 30.0)
    assert trimmer.trims == 1
