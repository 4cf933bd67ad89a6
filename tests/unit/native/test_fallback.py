"""The one fallback thread of the native channels (native/fallback.py, docs/native.md §5): every
channel's fallback on it, each in its own bounded queue, served in turn, closed on its own.

The handlers stand for a channel's Python path; gates (threading.Event) hold a handler where a
slow conversion would, so the orders asserted do not depend on timing.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from ros_gz_bridge_py.native.fallback import FallbackLane, FallbackWorker
from ros_gz_bridge_py.transport import MessageInfo
from ros_gz_bridge_py.transport.heap import BurstTrimmer

#: Upper bound of every wait for something that should happen.
WAIT = 10.0
INFO = MessageInfo("/fallen", "gz.msgs.StringMsg", "", "tcp://127.0.0.1:1", intra_process=False)


class Recorder:
    """Handlers that record (lane name, payload, thread) in order, each optionally held at a
    gate until the test opens it (then it stays open)."""

    def __init__(self) -> None:
        self.handled: list[tuple[str, bytes, str]] = []
        self.changed = threading.Condition()
        self.gates: dict[str, threading.Event] = {}
        self.entered = threading.Event()

    def handler(self, name: str, *, gated: bool = False) -> FallbackHandler:
        if gated:
            self.gates[name] = threading.Event()
        return FallbackHandler(self, name)

    def wait_for(self, count: int) -> list[tuple[str, bytes, str]]:
        with self.changed:
            assert self.changed.wait_for(lambda: len(self.handled) >= count, WAIT), self.handled
            return list(self.handled)


class FallbackHandler:
    def __init__(self, recorder: Recorder, name: str) -> None:
        self._recorder = recorder
        self._name = name

    def __call__(self, payload: bytes, info: MessageInfo) -> None:
        assert info is INFO
        gate = self._recorder.gates.get(self._name)
        if gate is not None:
            self._recorder.entered.set()
            assert gate.wait(WAIT)
        with self._recorder.changed:
            self._recorder.handled.append((self._name, payload, threading.current_thread().name))
            self._recorder.changed.notify_all()


@pytest.fixture
def worker() -> Iterator[FallbackWorker]:
    made = FallbackWorker(name="test-fallback")
    yield made
    thread = made.thread
    if thread is not None:
        thread.join(WAIT)


def _close_all(*lanes: FallbackLane[MessageInfo]) -> None:
    for lane in lanes:
        lane.close()


def test_every_lane_is_served_by_one_thread(worker: FallbackWorker) -> None:
    """Ten channels that fall back cost one thread, not ten (before: a thread per channel)."""
    recorder = Recorder()
    before = threading.active_count()
    lanes = [worker.lane(recorder.handler(f"lane{i}"), 10, 1 << 20, "/fallen") for i in range(10)]
    for i, lane in enumerate(lanes):
        lane.put(b"payload %d" % i, INFO)
    handled = recorder.wait_for(10)
    assert threading.active_count() <= before + 1
    assert {thread for _lane, _payload, thread in handled} == {"test-fallback"}
    assert sorted(payload for _lane, payload, _thread in handled) == sorted(
        b"payload %d" % i for i in range(10)
    )
    _close_all(*lanes)


def test_a_flooded_lane_does_not_starve_another(worker: FallbackWorker) -> None:
    """Lanes are served one payload each in turn: the light channel's payload waits for the
    flood's payload being handled and the one whose turn was asked before it came, not for
    the flood's hundred queued (before: a thread per channel; one thread serving queues in
    order of arrival would make it wait for all of them)."""
    recorder = Recorder()
    flood = worker.lane(recorder.handler("flood", gated=True), 1000, 1 << 20, "/fallen")
    light = worker.lane(recorder.handler("light"), 10, 1 << 20, "/fallen")
    flood.put(b"flood 0", INFO)
    assert recorder.entered.wait(WAIT)
    for i in range(1, 100):
        flood.put(b"flood %d" % i, INFO)
    light.put(b"light", INFO)
    recorder.gates["flood"].set()
    handled = recorder.wait_for(101)
    order = [lane for lane, _payload, _thread in handled]
    assert order[:4] == ["flood", "flood", "light", "flood"]
    assert [payload for _lane, payload, _thread in handled if _lane == "flood"] == [
        b"flood %d" % i for i in range(100)
    ]
    _close_all(flood, light)


def test_each_lane_keeps_its_own_bounds_and_counts_its_drops(worker: FallbackWorker) -> None:
    """While the thread is held on a payload, a lane keeps its newest ``size`` payloads and
    at most ``max_bytes`` of them; its drops are its own."""
    recorder = Recorder()
    held = worker.lane(recorder.handler("held", gated=True), 10, 1 << 20, "/fallen")
    counted = worker.lane(recorder.handler("counted"), 3, 1 << 20, "/fallen")
    weighed = worker.lane(recorder.handler("weighed"), 100, 2500, "/fallen")
    held.put(b"held", INFO)
    assert recorder.entered.wait(WAIT)
    for i in range(10):
        counted.put(b"counted %d" % i, INFO)
        weighed.put(b"%04d" % i + b"w" * 996, INFO)
    assert (held.dropped, counted.dropped, weighed.dropped) == (0, 7, 8)
    recorder.gates["held"].set()
    handled = recorder.wait_for(6)
    assert [payload for lane, payload, _thread in handled if lane == "counted"] == [
        b"counted 7",
        b"counted 8",
        b"counted 9",
    ]
    assert [payload[:4] for lane, payload, _thread in handled if lane == "weighed"] == [
        b"0008",
        b"0009",
    ]
    _close_all(held, counted, weighed)


def test_closing_a_lane_waits_for_none_of_another_lanes_payloads(worker: FallbackWorker) -> None:
    """A channel closing while the thread is held by another channel's slow conversion returns
    at once, and its queued payloads are never handled."""
    recorder = Recorder()
    slow = worker.lane(recorder.handler("slow", gated=True), 10, 1 << 20, "/fallen")
    closing = worker.lane(recorder.handler("closing"), 10, 1 << 20, "/fallen")
    slow.put(b"slow", INFO)
    assert recorder.entered.wait(WAIT)
    closing.put(b"never", INFO)
    closer = threading.Thread(target=closing.close)
    closer.start()
    closer.join(WAIT)  # the slow handler is held until after this: waiting for it would hang
    assert not closer.is_alive()
    closing.put(b"after the close", INFO)
    recorder.gates["slow"].set()
    slow.put(b"slow again", INFO)
    handled = recorder.wait_for(2)
    assert [lane for lane, _payload, _thread in handled] == ["slow", "slow"]
    assert len(closing.queue) == 0
    slow.close()


def test_closing_a_lane_waits_for_its_own_payload_being_handled(worker: FallbackWorker) -> None:
    """After close returns, no handler of the lane runs (the channel's publisher may go)."""
    recorder = Recorder()
    lane = worker.lane(recorder.handler("lane", gated=True), 10, 1 << 20, "/fallen")
    lane.put(b"being handled", INFO)
    lane.put(b"queued", INFO)
    assert recorder.entered.wait(WAIT)
    events: list[str] = []

    def close() -> None:
        lane.close()
        events.append("closed")

    closer = threading.Thread(target=close)
    closer.start()
    time.sleep(0.1)  # gives close the time to return early, were it to
    events.append("released")
    recorder.gates["lane"].set()
    closer.join(WAIT)
    assert events == ["released", "closed"]
    assert [payload for _lane, payload, _thread in recorder.handled] == [b"being handled"]


def test_the_thread_ends_with_the_last_lane_and_comes_back_with_the_next(
    worker: FallbackWorker,
) -> None:
    recorder = Recorder()
    first = worker.lane(recorder.handler("first"), 10, 1 << 20, "/fallen")
    first.put(b"1", INFO)
    recorder.wait_for(1)
    thread = worker.thread
    assert thread is not None
    first.close()
    thread.join(WAIT)
    assert not thread.is_alive()
    assert worker.thread is None
    second = worker.lane(recorder.handler("second"), 10, 1 << 20, "/fallen")
    second.put(b"2", INFO)
    assert [lane for lane, _payload, _thread in recorder.wait_for(2)] == ["first", "second"]
    second.close()


def test_a_handler_that_raises_leaves_the_thread_serving(
    worker: FallbackWorker, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder()
    record = recorder.handler("lane")

    def handler(payload: bytes, info: MessageInfo) -> None:
        if payload == b"bad":
            msg = "publisher gone"
            raise RuntimeError(msg)
        record(payload, info)

    lane = worker.lane(handler, 10, 1 << 20, "/fallen")
    lane.put(b"bad", INFO)
    lane.put(b"good", INFO)
    assert [payload for _lane, payload, _thread in recorder.wait_for(1)] == [b"good"]
    assert "the Python path of a payload that fell back failed" in caplog.text
    lane.close()


def test_the_thread_trims_after_a_burst_once_quiet() -> None:
    """A burst of fallbacks, then nothing: the thread trims once (it waits with a timeout only
    while a trim is pending)."""
    trimmed = threading.Event()
    worker = FallbackWorker(BurstTrimmer(trimmed.set, trim_after=2000), name="test-fallback")
    recorder = Recorder()
    lane = worker.lane(recorder.handler("lane"), 10, 1 << 20, "/fallen")
    lane.put(b"x" * 1000, INFO)
    lane.put(b"y" * 1000, INFO)
    recorder.wait_for(2)
    assert trimmed.wait(WAIT)
    lane.close()
