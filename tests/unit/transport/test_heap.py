"""Trimming the heap after a burst of large messages, never during a steady stream."""

from __future__ import annotations

from ros_gz_bridge_py.transport.heap import (
    IDLE_BEFORE_TRIM,
    RATE_WINDOW,
    TRIM_AFTER_BYTES,
    BurstTrimmer,
    trim_heap,
)


def _trims(events: list[tuple[float, int]]) -> list[float]:
    """The times of the trims when ``events`` (time, bytes received then; 0: an idle call)
    happen in order."""
    trims: list[float] = []
    now = [0.0]
    trimmer = BurstTrimmer(lambda: trims.append(now[0]))
    for now[0], size in events:
        if size:
            trimmer.received(size, now[0])
        trimmer.idle(now[0])
    return trims


def test_a_burst_is_trimmed_once_it_is_over() -> None:
    burst = [(0.01 * i, TRIM_AFTER_BYTES // 100 + 1) for i in range(100)]
    quiet = [(1.0 + 0.05 * i, 0) for i in range(100)]
    trims = _trims(burst + quiet)
    assert len(trims) == 1
    assert 1.0 + IDLE_BEFORE_TRIM <= trims[0] <= 1.0 + IDLE_BEFORE_TRIM + 2 * RATE_WINDOW


def test_a_light_stream_beside_the_burst_does_not_hold_its_memory() -> None:
    """The rogue's frames on the topic of a real 50 Hz publisher: the burst ends when the
    frames stop, although messages still arrive (before: every message put off the trim)."""
    burst = [(0.01 * i, TRIM_AFTER_BYTES // 100 + 1) for i in range(100)]
    light = [(1.0 + 0.02 * i, 700) for i in range(250)]
    trims = _trims(burst + light)
    assert len(trims) == 1
    assert trims[0] <= 1.0 + IDLE_BEFORE_TRIM + 2 * RATE_WINDOW


def test_a_steady_stream_of_large_messages_is_never_trimmed() -> None:
    camera = [(i / 30, 6_000_000) for i in range(300)]  # 10 s of 1080p at 30 Hz
    assert _trims(camera) == []


def test_small_traffic_is_never_trimmed() -> None:
    assert _trims([(0.0, TRIM_AFTER_BYTES - 1), (100.0, 0)]) == []


def test_running_totals_trim_once_a_burst_has_stopped_growing() -> None:
    """The native loop's form: each count gives the bytes read so far."""
    trimmer = BurstTrimmer(lambda: None)
    trimmer.read_so_far(TRIM_AFTER_BYTES // 2, 10.0)
    trimmer.read_so_far(TRIM_AFTER_BYTES, 10.5)
    trimmer.read_so_far(TRIM_AFTER_BYTES, 10.5 + IDLE_BEFORE_TRIM / 2)  # a short pause
    assert trimmer.trims == 0
    trimmer.read_so_far(TRIM_AFTER_BYTES + 1, 10.5 + IDLE_BEFORE_TRIM)  # and a trickle
    assert trimmer.trims == 1
    trimmer.read_so_far(TRIM_AFTER_BYTES + 2, 30.0)
    assert trimmer.trims == 1


def test_trim_heap_runs_here() -> None:
    assert isinstance(trim_heap(), bool)  # glibc: malloc_trim(0); elsewhere a no-op
