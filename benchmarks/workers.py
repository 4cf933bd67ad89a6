"""Benchmark endpoint processes: a ROS or Gazebo publisher or subscriber of one message kind.

``python -m benchmarks.workers ROLE TOPIC KIND SECONDS [--hz HZ] [--slow-ms MS] [--depth N]
[--qos-profile NAME] [--flood TOPIC --flood-kind KIND --flood-hz HZ --flood-lead S]`` with ROLE
one of ``ros-pub``, ``ros-sub``, ``gz-pub``, ``gz-sub``. Lines printed, in order: ``READY`` (the
endpoint exists), ``CONNECTED`` (publishers: a subscriber is matched), with ``--flood``
``FLOOD_START``, then ``START``, ``SENT n SECONDS s`` and with ``--flood`` ``FLOOD_SENT n``;
subscribers print ``MATCHED`` when they see a publisher and, on SIGTERM
or after SECONDS, the same ``STATS`` line as ``benchmarks.transport``. ROS ends use the speed
settings of the bridge executables (Fast DDS SHM profile, EventsExecutor, allocator tuning);
Gazebo ends use the backend ``GZ_TRANSPORT_IMPLEMENTATION`` names.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from benchmarks.payloads import (
    KINDS,
    GzPayloads,
    Kind,
    gz_stamp,
    now_ns,
    ros_stamp,
    ros_stamp_cdr,
    stamp_ros,
)
from benchmarks.transport import stats_line
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.speed import apply_fastdds_profile
from ros_gz_bridge_py.transport import MessageInfo, create_gz_node

#: How long a publisher waits for its first subscriber.
MATCH_WAIT = 15.0
#: Pause between the match and the first measured message (late discovery on the far side).
SETTLE = 0.5
NS_PER_S = 1_000_000_000


def say(line: str) -> None:
    print(line, flush=True)


class Recorder:
    """Latencies and arrival times of one subscriber, printed as a STATS line."""

    def __init__(self, slow_s: float) -> None:
        self.latencies: list[int] = []
        self.arrivals: list[int] = []
        self.total = 0
        self.slow_s = slow_s

    def record(self, stamp_ns: int, size: int) -> None:
        now = now_ns()
        self.latencies.append(now - stamp_ns)
        self.arrivals.append(now)
        self.total += size
        if self.slow_s:
            time.sleep(self.slow_s)

    def report(self) -> None:
        say(stats_line(list(self.latencies), list(self.arrivals), self.total))


def _pace(hz: float) -> Callable[[], None]:
    """A function that sleeps until the next send time (no-op when ``hz`` is 0)."""
    if hz <= 0:
        return lambda: None
    period = int(NS_PER_S / hz)
    next_send = [now_ns()]

    def wait() -> None:
        delay = next_send[0] - now_ns()
        if delay > 0:
            time.sleep(delay / NS_PER_S)
        next_send[0] += period

    return wait


@dataclass(frozen=True)
class FloodArgs:
    """``--flood TOPIC --flood-kind KIND [--flood-hz HZ] [--flood-lead S]``."""

    topic: str
    kind: Kind
    hz: float
    lead: float


class Flood:
    """A second stream of a publisher process, as the C++ peer's ``--flood`` (its
    ``testing/peer/flood.hh``): its own thread sends from its first subscriber on until
    :meth:`stop`."""

    def __init__(self, args: FloodArgs, connected: Callable[[], bool], send: Callable[[], None]):
        self._args = args
        self._stop = threading.Event()
        self._started = threading.Event()
        self.sent = 0
        self._thread = threading.Thread(target=self._run, args=(connected, send), daemon=True)
        self._thread.start()

    def _run(self, connected: Callable[[], bool], send: Callable[[], None]) -> None:
        while not connected() and not self._stop.is_set():
            time.sleep(0.01)
        self._started.set()
        pace = _pace(self._args.hz)
        while not self._stop.is_set():
            pace()
            send()
            self.sent += 1

    def wait_until_flowing(self) -> None:
        """Wait until the flood has sent for its lead time (FLOOD_START once it sends)."""
        if not self._started.wait(MATCH_WAIT):
            say("FLOOD_NO_CONNECTIONS")
            return
        say("FLOOD_START")
        time.sleep(self._args.lead)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()
        say(f"FLOOD_SENT {self.sent}")


def _publish_loop(
    seconds: float, hz: float, send: Callable[[], None], flood: Flood | None = None
) -> None:
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    if flood is not None:
        flood.wait_until_flowing()
    pace = _pace(hz)
    say("START")
    start = now_ns()
    end = start + int(seconds * NS_PER_S)
    sent = 0
    while not stop.is_set() and now_ns() < end:
        pace()
        send()
        sent += 1
    say(f"SENT {sent} SECONDS {(now_ns() - start) / NS_PER_S:.3f}")


def _ros_start() -> Any:
    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415 - loads rclpy
    from ros_gz_bridge_py.ros.runtime import tune_allocator  # noqa: PLC0415

    tune_allocator()
    apply_fastdds_profile(enabled=read_switches().fastdds_profile)
    import rclpy  # noqa: PLC0415
    from rclpy.signals import SignalHandlerOptions  # noqa: PLC0415

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    return rclpy


def _ros_qos(depth: int | None = None, profile: str | None = None) -> Any:
    from ros_gz_bridge_py.ros.qos import endpoint_qos  # noqa: PLC0415

    return endpoint_qos(profile, depth)


def _ros_flood(node: Any, args: FloodArgs | None) -> Flood | None:
    if args is None:
        return None
    publisher = node.create_publisher(args.kind.pair.ros_class, args.topic, _ros_qos())
    msg = args.kind.make_ros()

    def send() -> None:
        stamp_ros(args.kind, msg, now_ns())
        publisher.publish(msg)

    return Flood(args, lambda: publisher.get_subscription_count() > 0, send)


def ros_pub(
    topic: str, kind: Kind, seconds: float, hz: float, depth: int | None, *, flood: FloodArgs | None
) -> None:
    rclpy = _ros_start()
    node = rclpy.create_node(f"bench_pub_{os.getpid()}")
    publisher = node.create_publisher(kind.pair.ros_class, topic, _ros_qos(depth))
    msg = kind.make_ros()
    flooding = _ros_flood(node, flood)
    say("READY")
    deadline = time.monotonic() + MATCH_WAIT
    while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.02)
    if publisher.get_subscription_count() == 0:
        say("NO_CONNECTIONS")
        return
    say("CONNECTED")
    time.sleep(SETTLE)

    def send() -> None:
        stamp_ros(kind, msg, now_ns())
        publisher.publish(msg)

    _publish_loop(seconds, hz, send, flooding)
    time.sleep(0.5)
    if flooding is not None:
        flooding.stop()
    node.destroy_node()
    rclpy.try_shutdown()


def ros_sub(
    topic: str,
    kind: Kind,
    seconds: float,
    slow_s: float,
    depth: int | None,
    *,
    profile: str | None,
    raw: bool = False,
) -> None:
    """Spin on a daemon thread; the main thread waits for SIGTERM or ``seconds`` and reports,
    so the STATS line never depends on the executor shutting down cleanly under load.
    ``raw``: take the messages serialized (rclpy's ``raw=True``) and read only their stamp, so
    the subscriber's own cost is not rclpy's deserialization."""
    rclpy = _ros_start()
    from rclpy.task import Future  # noqa: PLC0415

    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415
    from ros_gz_bridge_py.ros.runtime import make_executor  # noqa: PLC0415

    node = rclpy.create_node(f"bench_sub_{os.getpid()}")
    recorder = Recorder(slow_s)

    def on_message(msg: Any) -> None:
        recorder.record(ros_stamp_cdr(kind, msg) if raw else ros_stamp(kind, msg), 0)

    qos = _ros_qos(depth, profile)
    node.create_subscription(kind.pair.ros_class, topic, on_message, qos, raw=raw)
    say("READY")
    _announce_match(lambda: node.count_publishers(topic) > 0)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    executor = make_executor(events=read_switches().events_executor)
    executor.add_node(node)
    never: Future = Future(executor=executor)

    def spin() -> None:
        while not stop.is_set():
            executor.spin_until_future_complete(never, timeout_sec=0.5)

    spinning = threading.Thread(target=spin, daemon=True)
    spinning.start()
    stop.wait(seconds)
    recorder.report()
    stop.set()
    spinning.join(timeout=2)
    # Leave the DDS graph in order: a reader that vanishes without a goodbye stays matched to
    # the bridge's writer until the lease expires, and the writer's shared-memory sends to its
    # dead port stall the next flow of that channel for about a second.
    try:
        node.destroy_node()
        rclpy.try_shutdown()
    finally:
        os._exit(0)  # nothing else of rclpy needs to wind down


def _announce_match(matched: Callable[[], bool]) -> None:
    def watch() -> None:
        deadline = time.monotonic() + MATCH_WAIT
        while time.monotonic() < deadline:
            if matched():
                say("MATCHED")
                return
            time.sleep(0.05)

    threading.Thread(target=watch, daemon=True).start()


def _gz_flood(node: Any, args: FloodArgs | None) -> Flood | None:
    if args is None:
        return None
    publisher = node.advertise(args.topic, args.kind.gz_type)
    payloads = GzPayloads(args.kind)
    return Flood(
        args, publisher.has_connections, lambda: publisher.publish_raw(payloads.payload(now_ns()))
    )


def gz_pub(topic: str, kind: Kind, seconds: float, hz: float, flood: FloodArgs | None) -> None:
    payloads = GzPayloads(kind)
    with create_gz_node() as node:
        publisher = node.advertise(topic, kind.gz_type)
        flooding = _gz_flood(node, flood)
        say("READY")
        deadline = time.monotonic() + MATCH_WAIT
        while not publisher.has_connections() and time.monotonic() < deadline:
            time.sleep(0.02)
        if not publisher.has_connections():
            say("NO_CONNECTIONS")
            return
        say("CONNECTED")
        time.sleep(SETTLE)
        send = lambda: publisher.publish_raw(payloads.payload(now_ns()))  # noqa: E731
        _publish_loop(seconds, hz, send, flooding)
        time.sleep(0.5)
        if flooding is not None:
            flooding.stop()


def gz_sub(topic: str, kind: Kind, seconds: float, slow_s: float) -> None:
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    parse = message_class(kind.gz_type).FromString
    recorder = Recorder(slow_s)

    def on_message(payload: bytes, _info: MessageInfo) -> None:
        recorder.record(gz_stamp(kind, parse(payload)), len(payload))

    with create_gz_node() as node:
        subscription = node.subscribe(topic, on_message, kind.gz_type)
        say("READY")
        _announce_match(lambda: bool(node.topic_info(topic)))
        stop.wait(seconds)
        subscription.close()
    recorder.report()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("role", choices=("ros-pub", "ros-sub", "gz-pub", "gz-sub"))
    parser.add_argument("topic")
    parser.add_argument("kind", choices=sorted(KINDS))
    parser.add_argument("seconds", type=float)
    parser.add_argument("--hz", type=float, default=0.0, help="publishers: rate (0: flat out)")
    parser.add_argument("--slow-ms", type=float, default=0.0, help="subscribers: work per message")
    parser.add_argument("--depth", type=int, default=None, help="ros ends: history depth")
    parser.add_argument("--qos-profile", help="ros-sub: a named profile (e.g. CLOCK)")
    parser.add_argument("--raw", action="store_true", help="ros-sub: take messages serialized")
    parser.add_argument("--flood", help="publishers: topic of a second stream (see Flood)")
    parser.add_argument("--flood-kind", choices=sorted(KINDS), default="image1080")
    parser.add_argument("--flood-hz", type=float, default=0.0, help="0: back to back")
    parser.add_argument("--flood-lead", type=float, default=3.0, help="seconds before START")
    args = parser.parse_args(argv)
    kind = KINDS[args.kind]
    flood = None
    if args.flood:
        flood = FloodArgs(args.flood, KINDS[args.flood_kind], args.flood_hz, args.flood_lead)
    if args.role == "ros-pub":
        ros_pub(args.topic, kind, args.seconds, args.hz, args.depth, flood=flood)
    elif args.role == "ros-sub":
        ros_sub(
            args.topic,
            kind,
            args.seconds,
            args.slow_ms / 1000,
            args.depth,
            profile=args.qos_profile,
            raw=args.raw,
        )
    elif args.role == "gz-pub":
        gz_pub(args.topic, kind, args.seconds, args.hz, flood)
    else:
        gz_sub(args.topic, kind, args.seconds, args.slow_ms / 1000)
    return 0


if __name__ == "__main__":
    sys.exit(main())
