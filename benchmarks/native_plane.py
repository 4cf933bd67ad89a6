"""The native data plane against the Python path, each in a bridge process of its own (issue 22).

Usage: ``.venv/bin/python -m benchmarks.native_plane [--seconds S] [--workload-seconds S]
[--workload-rounds N] [--clock-seconds S] [--rates HZ ...]``; writes the ``native_plane``
section of BENCHMARKS.md, stores its figures and draws ``benchmarks/plots/native_overload.png``.
Each phase runs with the native data plane (the default where the extension is built) and with
``ROS_GZ_BRIDGE_NATIVE=off`` in the bridge's environment (the Python path), a fresh bridge
each time; the status table (SIGUSR1) says which path each channel took and what it received,
published and dropped. The Gazebo ends are the C++ peer on Ignition Transport 11.

1. Overload: Odometry Gazebo -> ROS offered at rising rates to an rclpy subscriber.
2. The TurtleBot3 workload through the unchanged seed configuration: the bridge's CPU.
3. /clock at 1 kHz while Odometry floods the same Gazebo process and the same bridge.

``--subscriber`` is the ROS end of phase 2, which this module starts itself.
"""

from __future__ import annotations

import argparse
import itertools
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from benchmarks import plots
from benchmarks.bridged import Backend, bridge_process, flow_through
from benchmarks.costs import flow_key, per_message_ms
from benchmarks.harness import (
    GZ_ENDS,
    PYTHON_THREADS,
    ROOT,
    THREAD_GROUPS,
    CpuWindow,
    Flood,
    Flow,
    FlowFailure,
    FlowResult,
    bridge_argument,
    bridge_config,
    failed,
    topic_name,
)
from benchmarks.payloads import KINDS
from benchmarks.reference import GOAL_CLOCK_SHARE
from benchmarks.report import write_section
from benchmarks.results import load, store
from benchmarks.small_messages import PACED_DEPTH
from benchmarks.tables import SIZES, verdict
from benchmarks.workers import MATCH_WAIT
from benchmarks.workers import SETTLE as PUBLISH_SETTLE
from ros_gz_bridge_py.app.settings import NATIVE_ENV
from ros_gz_bridge_py.converters.registry import Pair, default_registry
from testing.gzpeer import PeerProcess, peer_binary, start_process, wait_for_line
from testing.run_env import run_env

#: The bridge environment of each path, over :func:`~benchmarks.harness.run_env`'s.
PATHS = {"native": {}, "Python": {NATIVE_ENV: "off"}}
#: The ROS ends of the overload phase: whether each takes the messages serialized. "rclpy"
#: deserializes every message as an application does and so tops out at its own rate on these
#: cores; "serialized" reads only the stamp (rclpy's ``raw=True``), so what it misses is what
#: the bridge did not carry.
SUBSCRIBERS = {"rclpy": False, "serialized": True}
OVERLOAD_RATES = (1000.0, 2000.0, 5000.0, 10000.0, 20000.0, 40000.0)
#: The history depth of the ROS subscriber and the channel's queues in the overload phase.
QUEUE = PACED_DEPTH
#: Issue 22: the native path delivers at least this share at this offered rate...
GOAL_SHARE, GOAL_SHARE_HZ = 0.95, 20000.0
#: ...and its delivered rate never falls as the offered rate rises; a fall smaller than this
#: share of the best lower rate's is read as the run-to-run noise of 2 shared cores.
FALL_TOLERANCE = 0.05
#: Issue 22: the TurtleBot3 workload costs the bridge at most this % of one core.
GOAL_WORKLOAD_CPU = 15.0
#: Issue 22's proxy for the C++ bridge: CPU per message at most this share of what an rclpy
#: publisher and an rclpy subscriber spend per message.
GOAL_PROXY = 0.4
TURTLEBOT_CONFIG = ROOT / "config" / "turtlebot3_waffle_bridge.yaml"
#: Channels the seed configuration makes (all of its entries).
TURTLEBOT_CHANNELS = 8
#: Seconds the workload publishes before and after the CPU window.
WORKLOAD_MARGIN = 1.0
CLOCK_HZ = 1000.0
#: The Odometry stream beside /clock, and how long it runs before the first clock message.
FLOOD_HZ, FLOOD_LEAD = 40000.0, 2.0
_TICK = os.sysconf("SC_CLK_TCK")
SPLIT = " / ".join([PYTHON_THREADS, *(name for name, _ in THREAD_GROUPS)])
#: Where the overload plot goes, relative to the repository root.
OVERLOAD_PNG = "benchmarks/plots/native_overload.png"


def path_backend(path: str) -> Backend:
    """ZeroMQ, the bridge on ``path`` (the Gazebo and ROS ends as every benchmark's)."""
    env = run_env()
    bridge_env = {key: value for key, value in env.items() if key != NATIVE_ENV}
    return Backend(f"ZeroMQ, {path} path", bridge_env | PATHS[path], env)


# --- the bridge's own counters ------------------------------------------------------------------


@dataclass(frozen=True)
class Counters:
    """A GZ->ROS channel's IN, OUT and DROPPED, and its PATH, from the status table."""

    received: int
    published: int
    dropped: int
    path: str

    def since(self, before: Counters) -> Counters:
        return Counters(
            self.received - before.received,
            self.published - before.published,
            self.dropped - before.dropped,
            self.path,
        )

    def text(self) -> str:
        return f"{self.received} / {self.published} / {self.dropped}"


def counters(bridge: PeerProcess | None, topics: Sequence[str]) -> dict[str, Counters]:
    """The status row of the bridge's GZ->ROS channel of each of ``topics`` (ROS names);
    the topics whose row did not come within 5 s are missing."""
    if bridge is None:
        return {}
    wanted = {topic.lstrip("/"): topic for topic in topics}
    before = len(bridge.output().splitlines())
    found: dict[str, Counters] = {}
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and len(found) < len(wanted):
        # Until the bridge spins, SIGUSR1 is ignored: ask again until a table comes.
        os.kill(bridge.pid, signal.SIGUSR1)
        time.sleep(0.3)
        for line in bridge.output().splitlines()[before:]:
            fields = line.split()
            if len(fields) >= 12 and fields[1] == "GZ->ROS" and fields[2].lstrip("/") in wanted:
                found[wanted[fields[2].lstrip("/")]] = Counters(
                    int(fields[5]), int(fields[6]), int(fields[8]), fields[-1]
                )
    return found


def counted_since(
    before: dict[str, Counters], after: dict[str, Counters], topic: str
) -> Counters | None:
    if topic not in before or topic not in after:
        return None
    return after[topic].since(before[topic])


def _threads(groups: dict[str, float] | None) -> str:
    """A bridge's CPU by thread group, % of one core (``SPLIT``'s order)."""
    if not groups:
        return "-"
    return " / ".join(f"{groups.get(name, 0.0):.0f}%" for name in SPLIT.split(" / "))


def thread_seconds(pid: int) -> dict[str, float]:
    """CPU seconds of each live thread of ``pid`` (scheduler run time), by ``name/tid``."""
    seconds = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm", encoding="utf-8") as comm:
                name = comm.read().strip()
            with open(f"/proc/{pid}/task/{tid}/schedstat", encoding="ascii") as schedstat:
                seconds[f"{name}/{tid}"] = int(schedstat.read().split()[0]) / 1e9
        except (OSError, ValueError, IndexError):  # the thread ended meanwhile
            continue
    return seconds


def busiest(before: dict[str, float], after: dict[str, float], wall: float, count: int = 5) -> str:
    """The ``count`` threads that ran most between two :func:`thread_seconds`, % of a core."""
    used = {name: (after[name] - before.get(name, 0.0)) / wall for name in after}
    top = sorted(used.items(), key=lambda item: -item[1])[:count]
    return ", ".join(f"`{name}` {100 * share:.1f}%" for name, share in top)


def idle_seconds() -> float:
    """Idle (and I/O wait) time of all the machine's CPUs so far (/proc/stat). Busy time is
    the wall time of all CPUs less this: /proc/stat's own busy columns are sampled at the
    tick and miss most of the short bursts of a process woken 1000 times a second (measured:
    4.8% of the machine for a process that ran 6.2% by its own run time), its idle time is
    kept exactly."""
    with open("/proc/stat", encoding="ascii") as stat:
        ticks = stat.readline().split()[1:]
    return (int(ticks[3]) + int(ticks[4])) / _TICK


class MachineWindow:
    """How busy all the machine's CPUs were, % of all of them, between :meth:`begin` and
    :meth:`end`; ``MachineWindow(seconds).begin`` ends by itself after ``seconds`` (a flow's
    ``during``, which runs once publishing started)."""

    def __init__(self, seconds: float | None = None) -> None:
        self._seconds = seconds
        self._start = (0.0, 0.0)
        self.percent: float | None = None

    def begin(self) -> None:
        self._start = (time.monotonic(), idle_seconds())
        if self._seconds is not None:
            timer = threading.Timer(self._seconds, self.end)
            timer.daemon = True
            timer.start()

    def end(self) -> None:
        wall = (time.monotonic() - self._start[0]) * (os.cpu_count() or 1)
        self.percent = 100 * (1 - (idle_seconds() - self._start[1]) / max(wall, 1e-9))


def _cpu(value: float | None) -> str:
    return "-" if value is None else f"{value:.0f}%"


# --- 1. overload --------------------------------------------------------------------------------


@dataclass(frozen=True)
class Point:
    """One offered rate through one path."""

    path: str
    hz: float
    seconds: float
    result: FlowResult
    counted: Counters | None
    #: The whole machine's CPU, % of all its cores, while publishing.
    machine: float | None = None
    #: The ROS end (a key of :data:`SUBSCRIBERS`).
    subscriber: str = "rclpy"

    @property
    def series(self) -> str:
        return f"{self.path} path, {self.subscriber} subscriber"

    @property
    def offered(self) -> float:
        """What the peer sent, per second."""
        return self.result.sent / self.seconds

    @property
    def delivered(self) -> float:
        """What the rclpy subscriber received, per second of publishing."""
        return self.result.received / self.seconds

    @property
    def published(self) -> float | None:
        """What the bridge published (its OUT counter), per second of publishing."""
        return None if self.counted is None else self.counted.published / self.seconds

    def cpu_per_message_us(self) -> float | None:
        if self.result.cpu is None or not self.result.received:
            return None
        return self.result.cpu / 100 / self.delivered * 1e6


def sweep(path: str, subscriber: str, seconds: float, rates: Sequence[float]) -> list[Point]:
    """Odometry at each of ``rates`` through one fresh bridge on ``path`` to ``subscriber``."""
    which = path_backend(path)
    topic = topic_name(f"native_overload_{path}_{subscriber}")
    arguments = bridge_config([(topic, "odometry", "gz2ros")], QUEUE)
    raw = SUBSCRIBERS[subscriber]
    points = []
    with bridge_process(arguments, which.bridge_env, channels=1) as bridge:
        for hz in rates:
            flow = Flow("gz-pub", "ros-sub", "odometry", seconds, hz, depth=QUEUE, raw=raw)
            before, machine = counters(bridge, [topic]), MachineWindow(seconds)
            result = flow_through(flow, topic, which, bridge, machine.begin)
            counted = counted_since(before, counters(bridge, [topic]), topic)
            points.append(Point(path, hz, seconds, result, counted, machine.percent, subscriber))
    return points


def _point_row(point: Point) -> str:
    r = point.result
    what = f"| {point.path} | {point.subscriber} | {point.hz / 1000:g} kHz"
    if r.error:
        return f"{what} | failed: {r.error} |||||||||||||"
    per = point.cpu_per_message_us()
    counted = point.counted
    return (
        f"{what} | {point.offered / 1000:.1f} | {r.received}/{r.sent} "
        f"| **{point.delivered / 1000:.2f}** | {r.share:.1%} "
        f"| {'-' if point.published is None else f'{point.published / 1000:.2f}'} "
        f"| {'-' if counted is None else counted.text()} "
        f"| {'-' if counted is None else counted.path} | {_cpu(r.cpu)} "
        f"| {'-' if per is None else f'{per:.0f}'} | {_threads(r.bridge_threads)} "
        f"| {_cpu(r.sub_cpu)} | {_cpu(point.machine)} | {r.median_us / 1000:.2f} "
        f"| {r.p99_us / 1000:.2f} |"
    )


OVERLOAD_HEADER = (
    "| path | ROS subscriber | offered | sent, kHz | delivered/sent | delivered, kHz | share "
    "| bridge published, kHz | bridge in / out / dropped | PATH column | bridge CPU "
    f"| bridge CPU per delivered message, µs | of which {SPLIT} threads "
    "| subscriber CPU | machine CPU | median ms | p99 ms |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def falls(points: Sequence[Point]) -> list[str]:
    """Where the delivered rate fell (beyond :data:`FALL_TOLERANCE`) below that of a lower
    offered rate."""
    found, best, best_hz = [], 0.0, 0.0
    for point in sorted(points, key=lambda p: p.hz):
        if point.result.error:
            continue
        if point.delivered < best * (1 - FALL_TOLERANCE):
            found.append(
                f"{point.delivered / 1000:.2f} kHz at {point.hz / 1000:g} kHz offered against "
                f"{best / 1000:.2f} kHz at {best_hz / 1000:g} kHz"
            )
        if point.delivered > best:
            best, best_hz = point.delivered, point.hz
    return found


def where_lost(point: Point) -> str:
    """What bounds a point that lost messages: the bridge (its counters) or its subscriber."""
    r, counted = point.result, point.counted
    if counted is None or r.error:
        return ""
    bridge_lost = r.sent - counted.published
    after_bridge = counted.published - r.received
    text = (
        f"of {r.sent} sent the bridge published {counted.published} (it dropped "
        f"{counted.dropped} in its queue; {max(bridge_lost - counted.dropped, 0)} never reached "
        f"it) and the {point.subscriber} subscriber took {r.received} of those "
        f"({r.received / max(counted.published, 1):.1%}), itself busy {_cpu(r.sub_cpu)} of a "
        f"core; the bridge {_cpu(r.cpu)} ({SPLIT} threads: {_threads(r.bridge_threads)}); "
        f"the machine's {os.cpu_count()} cores {_cpu(point.machine)} busy"
    )
    if after_bridge > bridge_lost:
        text += (
            ": most were lost after the bridge, between its reliable keep-last "
            f"{QUEUE} writer and a subscriber that takes fewer a second than it is sent"
        )
    return text


def overload_goals(points: list[Point]) -> list[str]:
    lines = []
    for subscriber in SUBSCRIBERS:
        native = {p.hz: p for p in points if p.path == "native" and p.subscriber == subscriber}
        what = (
            f"- Native delivers >= {GOAL_SHARE:.0%} at {GOAL_SHARE_HZ / 1000:g} kHz to the "
            f"{subscriber} subscriber"
        )
        at = native.get(GOAL_SHARE_HZ)
        if at is None or at.result.error:
            lines.append(f"{what}: not measured")
            continue
        share = at.result.share
        gap = f"{(GOAL_SHARE - share) * 100:.1f} percentage points"
        bound = "" if share >= GOAL_SHARE else f"; {where_lost(at)}"
        lines.append(
            f"{what}: {at.result.received}/{at.result.sent} = {share:.1%} — "
            f"{verdict(share >= GOAL_SHARE, gap)}{bound}"
        )
    for path, subscriber in itertools.product(PATHS, SUBSCRIBERS):
        mine = sorted(
            (p for p in points if p.path == path and p.subscriber == subscriber),
            key=lambda p: p.hz,
        )
        if not mine:
            continue
        fell = falls(mine)
        rates = ", ".join(f"{p.delivered / 1000:.2f}" for p in mine)
        what = "the goal" if path == "native" else "for comparison"
        published = [p.published for p in mine]
        rising = all(
            (later or 0) >= (earlier or 0) * (1 - FALL_TOLERANCE)
            for earlier, later in itertools.pairwise(published)
        )
        lines.append(
            f"- {mine[0].series}: the delivered rate never falls as the offered rate rises "
            f"({what}; falls within {FALL_TOLERANCE:.0%} count as noise): {rates} kHz — "
            f"{verdict(not fell, '; '.join(fell))}. What the bridge itself published: "
            + ", ".join("-" if rate is None else f"{rate / 1000:.2f}" for rate in published)
            + f" kHz ({'never falls' if rising else 'falls'})"
        )
    return lines


# --- 2. the TurtleBot3 workload -----------------------------------------------------------------


def _joint_states() -> Any:
    from sensor_msgs.msg import JointState  # noqa: PLC0415 - ROS imports only where used

    msg = JointState(name=["wheel_left_joint", "wheel_right_joint", "caster_back_joint"])
    msg.position, msg.velocity, msg.effort = [0.5, -0.5, 0.0], [1.0, 1.0, 0.0], [0.0] * 3
    return msg


def _tf() -> Any:
    from geometry_msgs.msg import TransformStamped  # noqa: PLC0415
    from tf2_msgs.msg import TFMessage  # noqa: PLC0415

    transform = TransformStamped(child_frame_id="base_footprint")
    transform.header.frame_id = "odom"
    transform.transform.rotation.w = 1.0
    return TFMessage(transforms=[transform])


@dataclass(frozen=True)
class Stream:
    """One topic of the workload: its Gazebo and ROS name in the seed configuration, its
    rate, where the peer writes the send time, and the ROS message the Gazebo one is made
    from (with the registry's own converter)."""

    topic: str
    ros_type: str
    gz_type: str
    hz: float
    stamp: str
    make_ros: Callable[[], Any]

    @property
    def pair(self) -> Pair:
        return default_registry().get(self.ros_type, self.gz_type)

    def message_file(self) -> str:
        path = ROOT / ".build" / "bench_messages" / f"turtlebot3_{self.topic}.pb"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(self.pair.to_gz(self.make_ros()).SerializeToString())
        return str(path)

    def publisher(self, seconds: float) -> list[str]:
        """The C++ peer publishing this stream for ``seconds`` as Gazebo Harmonic does (its
        type name on the wire), the message serialized anew each time."""
        ignition = self.gz_type.replace("gz.msgs.", "ignition.msgs.", 1)
        return [
            *(str(peer_binary()), "kind-pub", self.topic, ignition, self.message_file()),
            *(f"{seconds:g}", "--hz", f"{self.hz:g}", "--stamp", self.stamp),
            *("--wait", str(MATCH_WAIT), "--settle", str(PUBLISH_SETTLE)),
            *("--wire-type", self.gz_type),
        ]


STREAMS = (
    Stream(
        "clock", "rosgraph_msgs/msg/Clock", "gz.msgs.Clock", 1000.0, "sim", KINDS["clock"].make_ros
    ),
    Stream(
        "joint_states", "sensor_msgs/msg/JointState", "gz.msgs.Model", 1000.0, "header.stamp",
        _joint_states,
    ),
    Stream(
        "odom", "nav_msgs/msg/Odometry", "gz.msgs.Odometry", 20.0, "header.stamp",
        KINDS["odometry"].make_ros,
    ),
    Stream("tf", "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V", 20.0, "pose.0.header.stamp", _tf),
    Stream(
        "imu", "sensor_msgs/msg/Imu", "gz.msgs.IMU", 50.0, "header.stamp", KINDS["imu"].make_ros
    ),
)  # fmt: skip


@dataclass(frozen=True)
class Workload:
    """The workload through one path: the bridge's CPU over the window, and per topic what
    was sent, received and which path its channel took."""

    path: str
    seconds: float
    cpu: float | None = None
    threads: dict[str, float] | None = None
    sent: dict[str, int] | None = None
    received: dict[str, int] | None = None
    counted: dict[str, Counters] | None = None
    #: The busiest threads of the bridge over the window (:func:`busiest`).
    threads_by_cpu: str = ""
    machine: float | None = None
    error: str = ""


def workload(path: str, seconds: float) -> Workload:
    """The seed configuration's bridge on ``path`` under the workload's streams; its CPU over
    ``seconds`` while all of them publish."""
    try:
        return _workload(path, seconds)
    except FlowFailure as error:
        return Workload(path, seconds, error=failed(error).error)


def _workload(path: str, seconds: float) -> Workload:
    which = path_backend(path)
    arguments = ["--ros-args", "-p", f"config_file:={TURTLEBOT_CONFIG}"]
    topics = [stream.topic for stream in STREAMS]
    command = [sys.executable, "-m", "benchmarks.native_plane", "--subscriber"]
    with bridge_process(arguments, which.bridge_env, channels=TURTLEBOT_CHANNELS) as bridge:
        if bridge is None:
            return Workload(path, seconds, error="bridge did not start")
        sub = start_process(command, run_env())
        wait_for_line(sub, "^READY$", 30)
        wait_for_line(sub, "^MATCHED$", 20)
        time.sleep(3.0)  # as SETTLE_ROS: the bridge's writers reach the subscriber
        publishing = seconds + 2.5 * WORKLOAD_MARGIN
        publishers = [start_process(s.publisher(publishing), which.gz_env) for s in STREAMS]
        for publisher in publishers:
            wait_for_line(publisher, "^START$", MATCH_WAIT + 10)
        time.sleep(WORKLOAD_MARGIN)
        before = counters(bridge, topics)
        window = CpuWindow(bridge.pid, by_thread=True)
        each, began, machine = thread_seconds(bridge.pid), time.monotonic(), MachineWindow()
        window.begin()
        machine.begin()
        time.sleep(seconds)
        window.end()
        machine.end()
        top = busiest(each, thread_seconds(bridge.pid), time.monotonic() - began)
        after = counters(bridge, topics)
        sent = {
            stream.topic: int(wait_for_line(publisher, r"^SENT (\d+)", publishing + 10)[1])
            for stream, publisher in zip(STREAMS, publishers, strict=True)
        }
        time.sleep(1.0)  # the last messages drain
        sub.stop(grace=15)
        received = {
            topic: int(wait_for_line(sub, rf"^COUNT {topic} (\d+)$", 5)[1]) for topic in topics
        }
    counted = {t: c for t in topics if (c := counted_since(before, after, t)) is not None}
    return Workload(
        path, seconds, window.percent, window.groups, sent, received, counted, top,
        machine.percent,
    )  # fmt: skip


def _workload_row(run: Workload) -> str:
    if run.error or run.sent is None or run.received is None:
        return f"| {run.path} | failed: {run.error} |||||"
    sent, received, counted = run.sent, run.received, run.counted or {}
    topics = ", ".join(f"{t} {received[t]}/{sent[t]}" for t in sent)
    paths = ", ".join(f"{t} {c.path}" for t, c in counted.items()) or "-"
    return (
        f"| {run.path} | **{_cpu(run.cpu)}** | {_threads(run.threads)} | {topics} | {paths} "
        f"| {_cpu(run.machine)} |"
    )


WORKLOAD_HEADER = (
    f"| path | bridge CPU, % of a core | of which {SPLIT} threads | delivered/sent per "
    "topic | PATH column | machine CPU |\n|---|---|---|---|---|---|"
)


def _median_run(runs: list[Workload], path: str) -> Workload | None:
    """The run of ``path`` with the median CPU (the lower middle one of an even count)."""
    measured = sorted((run for run in runs if run.path == path and run.cpu), key=_cpu_of)
    return measured[(len(measured) - 1) // 2] if measured else None


def _cpu_of(run: Workload) -> float:
    return run.cpu or 0.0


def workload_goal(runs: list[Workload]) -> str:
    native = _median_run(runs, "native")
    what = f"- The TurtleBot3 workload costs the native bridge <= {GOAL_WORKLOAD_CPU:g}% of a core"
    if native is None or native.cpu is None:
        failed = next((run.error for run in runs if run.path == "native"), "no run")
        return f"{what}: not measured ({failed})"
    python = _median_run(runs, "Python")
    beside = "" if python is None else f" (the Python path: {_cpu_of(python):.1f}%)"
    each = ", ".join(f"{_cpu_of(r):.1f}" for r in runs if r.path == "native" and r.cpu)
    met = native.cpu <= GOAL_WORKLOAD_CPU
    line = (
        f"{what}: {native.cpu:.1f}% (the median of the rounds: {each}){beside} — "
        f"{verdict(met, f'{native.cpu - GOAL_WORKLOAD_CPU:.1f} points of a core')}"
    )
    if not met and native.threads:
        rate = sum(stream.hz for stream in STREAMS)
        line += (
            f"; by thread group ({SPLIT}): {_threads(native.threads)}, at {rate:g} messages a "
            f"second ({native.cpu / 100 / rate * 1e6:.0f} µs of CPU per message); the busiest "
            f"threads: {native.threads_by_cpu} (Python's threads, the channels' readers among "
            "them, carry the process's name)"
        )
    return line


def subscriber() -> None:
    """The ROS end of the workload: one rclpy node (the speed settings of the benchmark
    workers) with a subscription of the bridge's default QoS to each stream's topic. Prints
    READY, MATCHED once every topic has a publisher, and on SIGTERM ``COUNT topic n``."""
    from ros_gz_bridge_py.app.settings import read_switches  # noqa: PLC0415 - loads rclpy
    from ros_gz_bridge_py.ros.qos import endpoint_qos  # noqa: PLC0415
    from ros_gz_bridge_py.ros.runtime import (  # noqa: PLC0415
        make_executor,
        spin_until_stopped,
        tune_allocator,
    )
    from ros_gz_bridge_py.ros.speed import apply_fastdds_profile  # noqa: PLC0415

    tune_allocator()
    apply_fastdds_profile(enabled=read_switches().fastdds_profile)
    import rclpy  # noqa: PLC0415
    from rclpy.signals import SignalHandlerOptions  # noqa: PLC0415

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(f"native_plane_sub_{os.getpid()}")
    counts = {f"/{stream.topic}": 0 for stream in STREAMS}

    def counter(topic: str) -> Callable[[Any], None]:
        def count(_msg: Any) -> None:
            counts[topic] += 1

        return count

    for stream in STREAMS:
        topic = f"/{stream.topic}"
        node.create_subscription(
            stream.pair.ros_class, topic, counter(topic), endpoint_qos(None, None)
        )
    print("READY", flush=True)
    waiting: list[Any] = []

    def matched() -> None:
        if waiting and all(node.count_publishers(topic) for topic in counts):
            print("MATCHED", flush=True)
            node.destroy_timer(waiting.pop())

    waiting.append(node.create_timer(0.05, matched))
    executor = make_executor(events=read_switches().events_executor)
    executor.add_node(node)
    spin_until_stopped(executor)
    for topic, count in counts.items():
        print(f"COUNT {topic.lstrip('/')} {count}", flush=True)
    os._exit(0)  # nothing else of rclpy needs to wind down


# --- 3. /clock under overload -------------------------------------------------------------------


@dataclass(frozen=True)
class ClockRun:
    path: str
    result: FlowResult
    clock: Counters | None
    flood: Counters | None
    machine: float | None = None


def clock_under_flood(path: str, seconds: float) -> ClockRun:
    """/clock at 1 kHz to a default (depth 10) subscriber while the same Gazebo process
    sends Odometry at :data:`FLOOD_HZ` through the same bridge on ``path``."""
    which = path_backend(path)
    clock, odometry = topic_name(f"native_clock_{path}"), topic_name(f"native_flood_{path}")
    arguments = [
        bridge_argument(clock, "clock", "gz2ros"),
        bridge_argument(odometry, "odometry", "gz2ros"),
    ]
    flood = Flood("odometry", odometry, hz=FLOOD_HZ, lead=FLOOD_LEAD)
    flow = Flow("gz-pub", "ros-sub", "clock", seconds, CLOCK_HZ, flood=flood)
    with bridge_process(arguments, which.bridge_env) as bridge:
        before, machine = counters(bridge, [clock, odometry]), MachineWindow(seconds)
        result = flow_through(flow, clock, which, bridge, machine.begin)
        after = counters(bridge, [clock, odometry])
    return ClockRun(
        path, result, counted_since(before, after, clock), counted_since(before, after, odometry),
        machine.percent,
    )  # fmt: skip


def _clock_row(run: ClockRun) -> str:
    r = run.result
    if r.error:
        return f"| {run.path} | failed: {r.error} |||||||||||"
    flood = "-" if r.flood is None else f"{r.flood.received}/{r.flood.sent}"
    paths = " / ".join(c.path if c else "-" for c in (run.clock, run.flood))
    return (
        f"| {run.path} | {r.received}/{r.sent} | **{r.share:.1%}** | {r.median_us / 1000:.2f} "
        f"| {r.p99_us / 1000:.2f} | {run.clock.text() if run.clock else '-'} | {flood} "
        f"| {run.flood.text() if run.flood else '-'} | {paths} | {_cpu(r.cpu)} "
        f"| {_threads(r.bridge_threads)} | {_cpu(r.sub_cpu)} | {_cpu(run.machine)} |"
    )


CLOCK_HEADER = (
    "| path | /clock delivered/sent | share | median ms | p99 ms | /clock channel in / out / "
    "dropped | Odometry delivered/sent | Odometry channel in / out / dropped | PATH column "
    f"(clock / Odometry) | bridge CPU | of which {SPLIT} threads | /clock subscriber CPU "
    "| machine CPU |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def clock_goal(runs: list[ClockRun]) -> str:
    native = next((run for run in runs if run.path == "native"), None)
    what = f"- /clock >= {GOAL_CLOCK_SHARE:.0%} under the Odometry flood, native"
    if native is None or native.result.error:
        return f"{what}: not measured"
    r = native.result
    python = next((run.result for run in runs if run.path == "Python"), None)
    beside = "" if python is None or python.error else f" (the Python path: {python.share:.1%})"
    met = r.share >= GOAL_CLOCK_SHARE
    line = (
        f"{what}: {r.received}/{r.sent} = {r.share:.1%}{beside} — "
        f"{verdict(met, f'{(GOAL_CLOCK_SHARE - r.share) * 100:.1f} percentage points')}"
    )
    if not met and native.clock is not None:
        line += (
            f"; the clock channel received {native.clock.received}, published "
            f"{native.clock.published}, dropped {native.clock.dropped}, and its depth-10 "
            f"subscriber took {r.received} of those (p99 latency {r.p99_us / 1000:.1f} ms); "
            f"the bridge {_cpu(r.cpu)} ({SPLIT}: {_threads(r.bridge_threads)}), the "
            f"machine's {os.cpu_count()} cores {_cpu(native.machine)} busy"
        )
    return line


# --- the proxy goal, from the last costs run -----------------------------------------------------


#: The rows issue 22's proxy goal names: (direction, kind, rate).
PROXY_ROWS = (
    ("GZ->ROS", "odometry", 1000.0),
    ("GZ->ROS", "odometry", 5000.0),
    ("ROS->GZ", "twist", 1000.0),
    ("GZ->ROS", "tf20", 1000.0),
    ("GZ->ROS", "imu", 1000.0),
)


def proxy_lines() -> list[str]:
    """Issue 22's proxy goal judged on the rows ``benchmarks.costs`` last stored."""
    stored = load("costs")
    if stored is None:
        return ["- not measured yet (`benchmarks.costs`)"]
    lines = [f"From `benchmarks.costs` ({stored.run_line()}):"]
    for way, kind, hz in PROXY_ROWS:
        flow = stored.flow(flow_key(way, kind, hz))
        ceiling = stored.flow(flow_key("ceiling", kind, hz))
        if flow is None or ceiling is None:
            lines.append(f"- {SIZES[kind]} {way} at {hz / 1000:g} kHz: not measured")
            continue
        cost = per_message_ms(flow.cpu, hz, flow)
        ends = [per_message_ms(cpu, hz, ceiling) for cpu in (ceiling.pub_cpu, ceiling.sub_cpu)]
        if cost is None or ends[0] is None or ends[1] is None:
            continue
        bar = GOAL_PROXY * (ends[0] + ends[1])
        lines.append(
            f"- {SIZES[kind]} {way} at {hz / 1000:g} kHz: {cost:.3f} ms per message "
            f"({flow.received}/{flow.sent} delivered); bar {GOAL_PROXY:g} x ({ends[0]:.3f} + "
            f"{ends[1]:.3f}) = {bar:.3f} ms — "
            f"{verdict(cost <= bar, f'{cost - bar:.3f} ms ({cost / bar:.1f}x the bar)')}"
        )
    return lines


# --- the report ---------------------------------------------------------------------------------


def _plot(points: list[Point]) -> str:
    names = dict.fromkeys(p.series for p in points)
    series = {
        f"{name}, delivered": [
            (p.hz / 1000, p.delivered / 1000) for p in points if p.series == name
        ]
        for name in names
    }
    series |= {  # what the bridge published does not depend on the subscriber: one line a path
        f"{path} path, published by the bridge ({subscriber} subscriber)": [
            (p.hz / 1000, p.published / 1000)
            for p in points
            if p.path == path and p.subscriber == subscriber and p.published is not None
        ]
        for path, subscriber in ((path, list(SUBSCRIBERS)[-1]) for path in PATHS)
    }
    try:
        drawn = plots.native_overload_plot(series, OVERLOAD_PNG)
    except ImportError:
        return "Plot not drawn: matplotlib is missing (`make bench` installs `.[bench]`)."
    return f"![Odometry Gazebo -> ROS: delivered against offered, native and Python]({drawn})"


def section(
    points: list[Point], runs: list[Workload], clocks: list[ClockRun], args: argparse.Namespace
) -> str:
    flags = (
        f" --seconds {args.seconds:g} --workload-seconds {args.workload_seconds:g}"
        f" --workload-rounds {args.workload_rounds}"
        f" --clock-seconds {args.clock_seconds:g}"
    )
    rates = ", ".join(f"{hz / 1000:g}" for hz in args.rates)
    streams = ", ".join(f"/{s.topic} ({s.gz_type}) at {s.hz:g} Hz" for s in STREAMS)
    return f"""## The native data plane against the Python path (issue 22)

Command: `.venv/bin/python -m benchmarks.native_plane{flags}`

Every phase runs twice, each time in a fresh bridge process: with the native data plane (on
by default where the extension is built, docs/native.md) and with `ROS_GZ_BRIDGE_NATIVE=off`
in the bridge's environment (the Python path). The PATH column is the bridge's own status
table (SIGUSR1), as are its in / out / dropped counters over the row; on both paths "in"
counts the messages the channel took from its queue, "dropped" those the queue let go,
oldest first, before any work on them. Bridge CPU is % of one core over the publishing window
(/proc/<pid>/stat), split by thread (/proc/<pid>/task/<tid>/schedstat): the Python threads
(on the native path also the C loop, which runs on the channel's reader thread with the GIL
released), libzmq's I/O thread, Fast DDS's threads. Machine CPU: all {os.cpu_count()} cores'
busy time over the same window, % of all of them (wall time less /proc/stat's idle time;
other work on the machine included). {GZ_ENDS}

### 1. Overload: Odometry Gazebo -> ROS at rising offered rates

The C++ peer offers Odometry at {rates} kHz for {args.seconds:g} s each (paced, serialized
anew each time) through one channel with queues of {QUEUE} (YAML `publisher_queue` /
`subscriber_queue`, as `costs`' rows) to an rclpy subscriber of depth {QUEUE}, a fresh bridge
for each path and subscriber: the *rclpy* subscriber deserializes every message (as an
application does, and so tops out at its own rate on these cores); the *serialized* one takes
them serialized (`raw=True`) and reads only the stamp, so what it misses is what the bridge did
not carry. Delivered = what the subscriber received per second of publishing; CPU per
delivered message = bridge CPU / delivered rate.

{OVERLOAD_HEADER}
{chr(10).join(_point_row(point) for point in points)}

{_plot(points)}

Goals (issue 22):
{chr(10).join(overload_goals(points))}

### 2. The TurtleBot3 workload through the seed configuration

`config/turtlebot3_waffle_bridge.yaml` unchanged ({TURTLEBOT_CHANNELS} channels); one C++ peer
process per stream, Harmonic type names on the wire: {streams}; the other entries (scan,
camera_info, cmd_vel) stay idle. One rclpy process subscribes to the five topics (reliable,
keep-last 10, the bridge's default). Bridge CPU over {args.workload_seconds:g} s while all
streams publish; {args.workload_rounds} rounds a path, alternating, each with a fresh bridge (the
figure moves by a few points from run to run on these shared cores: the median is judged).

{WORKLOAD_HEADER}
{chr(10).join(_workload_row(run) for run in runs)}

Goal (issue 22):
{workload_goal(runs)}

### 3. /clock at 1 kHz while Odometry floods the same Gazebo process and bridge

One Gazebo publisher process sends /clock at {CLOCK_HZ:g} Hz for {args.clock_seconds:g} s and,
from another thread (`kind-pub --flood`), Odometry at {FLOOD_HZ / 1000:g} kHz from
{FLOOD_LEAD:g} s before the first clock message; one bridge carries both (command-line
entries, default queues), each to an rclpy subscriber of depth 10.

{CLOCK_HEADER}
{chr(10).join(_clock_row(run) for run in clocks)}

Goal (issue 22):
{clock_goal(clocks)}

### CPU per message against the rclpy ends (issue 22's proxy)

Goal: bridge CPU per message <= {GOAL_PROXY:g} x (rclpy publisher + rclpy subscriber CPU per
message at the same rate, the same run), judged on the Gazebo -> ROS rows of the `costs`
section (its bridge ran with the native data plane on, the default).
{chr(10).join(proxy_lines())}
"""


def _stored(
    points: list[Point], runs: list[Workload], clocks: list[ClockRun]
) -> tuple[dict[str, FlowResult], dict[str, float]]:
    """The flows and figures kept in ``benchmarks/results.json``."""
    flows = {f"overload {p.path} {p.subscriber} {p.hz:g}": p.result for p in points}
    flows |= {f"clock {run.path}": run.result for run in clocks}
    medians = [run for path in PATHS if (run := _median_run(runs, path)) is not None]
    numbers = {f"workload {run.path} cpu": run.cpu for run in medians if run.cpu is not None}
    for run in medians:
        for topic, count in (run.received or {}).items():
            numbers[f"workload {run.path} {topic} received"] = float(count)
            numbers[f"workload {run.path} {topic} sent"] = float((run.sent or {})[topic])
    return flows, numbers


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="publishing per offered rate")
    parser.add_argument("--workload-seconds", type=float, default=10.0, help="CPU window")
    parser.add_argument(
        "--workload-rounds", type=int, default=3, help="workload runs per path (median judged)"
    )
    parser.add_argument("--clock-seconds", type=float, default=5.0, help="clock publishing")
    parser.add_argument("--rates", type=float, nargs="+", default=list(OVERLOAD_RATES))
    parser.add_argument("--subscriber", action="store_true", help="the workload's ROS end")
    args = parser.parse_args(argv)
    if args.subscriber:
        subscriber()
        return 0
    load_before = os.getloadavg()[0]
    points = [
        point
        for path, subscriber in itertools.product(PATHS, SUBSCRIBERS)
        for point in sweep(path, subscriber, args.seconds, sorted(args.rates))
    ]
    runs = [
        workload(path, args.workload_seconds) for _ in range(args.workload_rounds) for path in PATHS
    ]
    clocks = [clock_under_flood(path, args.clock_seconds) for path in PATHS]
    write_section("native_plane", section(points, runs, clocks, args))
    flows, numbers = _stored(points, runs, clocks)
    store("native_plane", flows, load_before, numbers)
    return 0


if __name__ == "__main__":
    sys.exit(main())
