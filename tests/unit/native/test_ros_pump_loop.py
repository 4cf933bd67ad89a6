"""A loop (loop.c) of ROS -> Gazebo channels and one channel's sends (ros_pump_loop.c), driven
from the test thread against a real rcl subscription and real ZeroMQ sockets (ros_pump_rig.py;
docs/native.md §7). Faults in sending are those libzmq reports: a terminated context for real,
and a frame refused mid-message through a ``zmq_send`` that wraps the real one and refuses the
frame a test names (the loop takes its functions by address, as from the libraries rclpy and
pyzmq loaded).
"""

from __future__ import annotations

import ctypes
import errno
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.transport.budget import TURN_MESSAGES
from tests.unit.native.ros_pump_rig import (
    BUDGET,
    LONG_SLICE,
    SEND,
    SENDER,
    TOPIC,
    TYPE,
    WAIT,
    Channel,
    functions,
    libzmq,
    run_until,
)

pytestmark = pytest.mark.ros


@pytest.fixture
def channels(native: Any, ros_context: Any) -> Iterator[Callable[..., Channel]]:
    made: list[Channel] = []

    def make(name: str, send: int | None = None) -> Channel:
        channel = Channel(native, ros_context, f"{name}_{uuid.uuid4().hex[:8]}", send)
        made.append(channel)
        return channel

    yield make
    for channel in made:
        channel.close()


def test_methods_of_uninitialised_objects_raise(native: Any) -> None:
    pump = native.RosPump.__new__(native.RosPump)
    calls = (pump.counts, pump.take_handed, lambda: pump.set_active(set()),
             lambda: pump.ignore([]), lambda: pump.send(TYPE, b""))  # fmt: skip
    for call in calls:
        with pytest.raises(RuntimeError, match="not initialised"):
            call()
    loop = native.Loop.__new__(native.Loop)
    for call in (lambda: loop.run(0, []), loop.wake, loop.size, lambda: loop.add(pump)):
        with pytest.raises(RuntimeError, match="not initialised"):
            call()
    with pytest.raises(TypeError, match="an initialised Pump or RosPump"):
        native.Loop(*BUDGET).add(pump)


def test_init_twice_raises(native: Any, channels: Callable[..., Channel]) -> None:
    channel = channels("twice")
    with pytest.raises(RuntimeError, match="initialised once"):
        channel.pump.__init__(functions(), 1, 1, [], 0.0)
    loop = native.Loop(*BUDGET)
    with pytest.raises(RuntimeError, match="initialised once"):
        loop.__init__(*BUDGET)


def test_messages_of_several_channels_are_sent_whole(
    native: Any, channels: Callable[..., Channel]
) -> None:
    loop = native.Loop(*BUDGET)
    first, second = channels("first"), channels("second")
    for channel in (first, second):
        loop.add(channel.pump)
        channel.remove_from(loop)
    assert loop.size() == 2
    for index in range(5):
        first.publish(f"one {index}")
        second.publish(f"two {index}")
    run_until(
        loop,
        lambda _m: first.pump.counts().published == 5 == second.pump.counts().published,
        "5 each",
    )
    for channel in (first, second):
        messages = channel.messages(5)
        assert len(messages) == 5
        assert all(m[0] == TOPIC and m[1] == SENDER and m[3] == TYPE for m in messages)
    assert loop.remove(first.pump) is True
    assert loop.remove(first.pump) is False  # once only
    first.publish("not taken")
    second.publish("taken")
    run_until(loop, lambda _m: second.pump.counts().published == 6, "the channel left")
    assert first.pump.counts().received == 5


def test_a_terminated_context_takes_the_channel_off_and_the_loop_goes_on(
    native: Any, channels: Callable[..., Channel]
) -> None:
    loop = native.Loop(*BUDGET)
    doomed, other = channels("doomed"), channels("other")
    for channel in (doomed, other):
        loop.add(channel.pump)
        channel.remove_from(loop)
    libzmq().zmq_ctx_shutdown(ctypes.c_void_p(doomed.zmq.underlying))
    doomed.publish("into a terminated context")
    broken = native.EVENT_BROKEN
    run_until(loop, lambda r: any(p is doomed.pump and e & broken for p, e in r), "failure")
    assert doomed.pump.failure == zmq.ETERM
    counts = doomed.pump.counts()
    assert (counts.received, counts.published, counts.send_failures) == (1, 0, 1)
    doomed.publish("after the failure")  # not taken: the loop does not wake for it
    other.publish("still carried")
    run_until(loop, lambda _m: other.pump.counts().published == 1, "the other channel")
    assert doomed.pump.counts().received == 1
    assert loop.remove(doomed.pump) is True


def _refusing(frame: int, code: int, times: int) -> tuple[Any, list[int]]:
    """A zmq_send that refuses its ``frame``-th call (from 1) ``times`` times with ``code``."""
    real = libzmq().zmq_send
    real.restype = ctypes.c_int
    real.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    calls: list[int] = []

    def send(sock: int, data: int, length: int, flags: int) -> int:
        calls.append(flags)
        if len(calls) >= frame and len(calls) < frame + times:
            ctypes.set_errno(code)
            return -1
        return int(real(sock, data, length, flags))

    return SEND(send), calls


def test_a_frame_refused_mid_message_is_not_published_and_leaves_no_part(
    native: Any, channels: Callable[..., Channel]
) -> None:
    send, calls = _refusing(frame=7, code=errno.EAGAIN, times=1)  # the 3rd frame of the 2nd
    address = ctypes.cast(send, ctypes.c_void_p).value
    channel = channels("mid_message", send=address)
    loop = native.Loop(*BUDGET)
    loop.add(channel.pump)
    channel.remove_from(loop)
    for index in range(3):
        channel.publish(f"message {index}")
    broken = native.EVENT_BROKEN
    reported = run_until(loop, lambda r: any(e & broken for _p, e in r), "the failure")
    assert [e & broken for _p, e in reported] == [broken]  # reported once: slept on no more
    assert channel.pump.failure == errno.EAGAIN
    counts = channel.pump.counts()
    assert (counts.published, counts.send_failures) == (1, 1)
    assert counts.received == 2  # the channel took nothing after its socket was left uncertain
    assert all(flags & zmq.DONTWAIT for flags in calls)
    assert [(len(m), m[2]) for m in channel.messages(1)] == [(4, b"\x12\tmessage 0")]
    loop.remove(channel.pump)


def test_an_interrupted_frame_is_sent_again(native: Any, channels: Callable[..., Channel]) -> None:
    send, _calls = _refusing(frame=3, code=errno.EINTR, times=2)
    channel = channels("interrupted", send=ctypes.cast(send, ctypes.c_void_p).value)
    loop = native.Loop(*BUDGET)
    loop.add(channel.pump)
    channel.remove_from(loop)
    channel.publish("once")
    run_until(loop, lambda _m: channel.pump.counts().published == 1, "the message")
    messages = channel.messages(1)
    assert [len(m) for m in messages] == [4]
    assert messages[0][2] == b"\x12\x04once"
    assert channel.pump.counts().send_failures == 0
    loop.remove(channel.pump)


def test_a_pass_gives_each_channel_its_budget_and_a_wake_ends_the_run(
    native: Any, channels: Callable[..., Channel]
) -> None:
    loop = native.Loop(*LONG_SLICE)
    flooded = [channels("flood_a"), channels("flood_b")]
    for channel in flooded:
        for index in range(100):
            channel.publish(f"flood {index}")
    time.sleep(0.5)  # the samples reach both subscriptions' queues (100 deep)
    for channel in flooded:
        loop.add(channel.pump)
        channel.remove_from(loop)
    woken, _reported = loop.run(0, [])  # one pass: the backlog still queued
    assert not woken
    assert [channel.pump.counts().received for channel in flooded] == [TURN_MESSAGES] * 2
    loop.wake()
    assert loop.run(60_000, []) == (True, [])  # at once, before a pass
    assert [channel.pump.counts().received for channel in flooded] == [TURN_MESSAGES] * 2
    run_until(loop, lambda _m: all(c.pump.counts().received == 100 for c in flooded), "the rest")


def test_a_member_that_fired_is_turned_before_the_backlog_goes_on(
    native: Any, channels: Callable[..., Channel]
) -> None:
    """A pass turns the members whose descriptors fired first, then the backlog in turn for one
    slice, round robin across passes (loop.c, pass): a quiet topic's message does not wait for
    every flooded channel's turn. A budget of one message and one nanosecond makes a pass one
    turn of each fired member and one backlog turn."""
    loop = native.Loop(1, 1)
    flooded = [channels(f"flood_{index}") for index in range(3)]
    quiet = channels("quiet")
    for channel in flooded:
        for index in range(10):
            channel.publish(f"flood {index}")
    quiet.publish("tick")
    time.sleep(0.5)  # the samples reach every subscription's queue

    def received() -> list[int]:
        return [channel.pump.counts().received for channel in (*flooded, quiet)]

    for channel in flooded:
        loop.add(channel.pump)
        channel.remove_from(loop)
    loop.run(0, [])  # the three fired: one turn each, then each has a backlog
    assert received() == [1, 1, 1, 0]
    loop.add(quiet.pump)
    quiet.remove_from(loop)
    loop.run(0, [])
    assert received() == [2, 1, 1, 1]  # the quiet one first, then one backlog turn
    loop.run(0, [])
    assert received() == [2, 2, 1, 1]  # the backlog goes on where it stopped
    loop.run(0, [])
    assert received() == [2, 2, 2, 1]


def test_channels_join_and_leave_while_the_loop_runs_and_the_others_keep_flowing(
    native: Any, channels: Callable[..., Channel]
) -> None:
    loop = native.Loop(*BUDGET)
    steady, churned = channels("steady"), channels("churned")
    loop.add(steady.pump)
    steady.remove_from(loop)
    churned.remove_from(loop)
    stop = threading.Event()

    def run() -> None:
        while not stop.is_set():
            loop.run(20, [])

    runner = threading.Thread(target=run, name="test-loop", daemon=True)
    runner.start()
    try:
        for index in range(50):
            assert loop.add(churned.pump) is None
            for k in range(20):
                churned.publish(f"churn {index} {k}")
            steady.publish(f"steady {index}")
            assert loop.remove(churned.pump) is True
        deadline = time.monotonic() + WAIT
        while steady.pump.counts().published < 50 and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        stop.set()
        runner.join()
    assert steady.pump.counts().published == 50
    assert loop.size() == 1
    texts = [m[2] for m in steady.messages(50)]
    assert texts == [
        b"\x12" + bytes([len(t)]) + t for t in (f"steady {i}".encode() for i in range(50))
    ]
