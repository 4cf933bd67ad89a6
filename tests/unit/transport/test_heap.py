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


def test_a_channel_told_only_when_it_moves_trims_once_its_burst_is_over() -> None:
    """The native loop's form: at each count (here every 0.25 s; the loop counts once a
    second) a channel that moved is told the bytes it read since the last; only while a trim
    is pending is it told the time at counts where it did not move."""
    trimmer = BurstTrimmer(lambda: None)
    now = 10.0
    for _ in range(8):  # 2 s of a burst
        trimmer.received(TRIM_AFTER_BYTES // 8, now)
        trimmer.idle(now)
        now += 0.25
    assert trimmer.pending
    trimmer.idle(now)  # the first quiet count: 0.25 s after the burst
    assert trimmer.trims == 0
    now += 1.0
    trimmer.received(100, now)  # a trickle
    trimmer.idle(now)
    assert (trimmer.trims, trimmer.pending) == (1, False)


def test_a_burst_after_a_long_silence_is_not_trimmed_before_a_quiet_second() -> None:
    """The bytes of a channel that moved after 100 s at rest are its burst's, not 100 s'
    worth of a trickle (before: measured over the silence, the burst looked quiet and was
    trimmed at once, while it might still go on)."""
    trims: list[float] = []
    now = [0.0]
    trimmer = BurstTrimmer(lambda: trims.append(now[0]))
    trimmer.received(1000, 0.0)
    now[0] = 100.0
    trimmer.received(TRIM_AFTER_BYTES, now[0])  # read within one count
    for now[0] in (100.0, 100.25, 100.5, 101.0, 101.25, 101.5):
        trimmer.idle(now[0])
    assert trims == [100.0 + RATE_WINDOW + IDLE_BEFORE_TRIM]  # a quiet second after its window


def test_a_trim_is_pending_from_the_threshold_until_it_is_done() -> None:
    trimmer = BurstTrimmer(lambda: None, trim_after=1000)
    trimmer.received(999, 0.0)
    assert not trimmer.pending
    trimmer.received(1, 0.0)
    assert trimmer.pending
    trimmer.idle(5.0)
    assert (trimmer.trims, trimmer.pending) == (1, False)


def test_trim_heap_runs_here() -> None:
    assert isinstance(trim_heap(), bool)  # glibc: malloc_trim(0); elsewhere a no-op
