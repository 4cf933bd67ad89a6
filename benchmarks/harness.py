"""Driving one benchmark flow: endpoint processes, the bridge, CPU and RSS from /proc.

A flow is one publisher process and one subscriber process (``benchmarks.workers``), with or
without a bridge process between them. The bridge's CPU is read from ``/proc/<pid>/stat``
over the publishing window; its RSS from ``/proc/<pid>/status``.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import re
import sys
import time
import uuid
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pytest

from benchmarks.bridge_threads import LIBZMQ_THREAD
from benchmarks.payloads import KINDS, gz_message
from benchmarks.transport import LARGE_HWM, STATS_LINE
from benchmarks.workers import MATCH_WAIT
from benchmarks.workers import SETTLE as PUBLISH_SETTLE
from ros_gz_bridge_py.ros.speed import remove_zombie_segments
from testing.gzpeer import PeerProcess, peer_binary, start_process, stop_processes, wait_for_line
from testing.procstat import cpu_seconds

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent
#: Seconds between a subscriber seeing the bridge and the publisher starting (connections).
SETTLE = 1.0
#: The same for an rclpy subscriber of the bridge's publisher. It sees the bridge's writer
#: before that writer delivers to it: with 1 s, 6 of 8 paced 1080p flows on a reused channel
#: lost their first frames or stalled ~350 ms at the start (the bridge had published them
#: all); with 3 s, none of 8 did.
SETTLE_ROS = 3.0
LARGE_KINDS = frozenset({"image640", "image1080", "cloud1mb"})
#: Errors a flow may end with; it is then reported as failed and the run goes on.
FlowFailure = (Exception, pytest.fail.Exception)


def topic_name(stem: str) -> str:
    return f"/bench_{stem}_{os.getpid()}_{uuid.uuid4().hex[:6]}"


#: Thread groups of a bridge process, by the start of the thread's name (``comm``): the
#: threads libzmq and Fast DDS start name themselves; Python's threads keep the process name.
THREAD_GROUPS = (("libzmq I/O", re.compile(LIBZMQ_THREAD)), ("Fast DDS", re.compile(r"dds\.")))
PYTHON_THREADS = "Python"


def thread_group_seconds(pid: int) -> dict[str, float]:
    """CPU seconds of ``pid``'s live threads by group (:data:`THREAD_GROUPS`, the rest
    :data:`PYTHON_THREADS`), from the scheduler's nanosecond run time (``schedstat``)."""
    seconds = dict.fromkeys([PYTHON_THREADS, *(name for name, _ in THREAD_GROUPS)], 0.0)
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm", encoding="utf-8") as comm:
                name = comm.read().strip()
            with open(f"/proc/{pid}/task/{tid}/schedstat", encoding="ascii") as schedstat:
                run_ns = int(schedstat.read().split()[0])
        except (OSError, ValueError, IndexError):  # the thread ended meanwhile
            continue
        group = next((g for g, start in THREAD_GROUPS if start.match(name)), None)
        seconds[group or PYTHON_THREADS] += run_ns / 1e9
    return seconds


class CpuWindow:
    """CPU share (percent of one core) of ``pid`` between :meth:`begin` and :meth:`end`;
    with ``by_thread``, also of each thread group (:func:`thread_group_seconds`)."""

    def __init__(self, pid: int | None, *, by_thread: bool = False) -> None:
        self.pid = pid
        self._by_thread = by_thread
        self._start = (0.0, 0.0)
        self._groups: dict[str, float] = {}
        self.percent: float | None = None
        self.groups: dict[str, float] | None = None

    def begin(self) -> None:
        if self.pid is not None:
            if self._by_thread:
                self._groups = thread_group_seconds(self.pid)
            self._start = (time.monotonic(), cpu_seconds(self.pid))

    def end(self) -> None:
        if self.pid is not None:
            wall = max(time.monotonic() - self._start[0], 1e-9)
            self.percent = 100 * (cpu_seconds(self.pid) - self._start[1]) / wall
            if self._by_thread:
                now = thread_group_seconds(self.pid)
                self.groups = {g: 100 * (now[g] - self._groups[g]) / wall for g in now}


# --- processes --------------------------------------------------------------------------------


#: The sentence every report uses to say what its Gazebo ends are.
GZ_ENDS = (
    "Gazebo ends: on ZeroMQ, the C++ peer on the real Ignition Transport 11 (`testing/peer`, "
    "modes kind-pub and kind-sub), which serializes every message anew as a simulator does "
    "(an image with a gz-sensors camera's header: stamp, `frame_id`, `seq`); on Zenoh, our "
    "Python workers (`benchmarks.workers`; Fortress has no Zenoh backend)."
)


def uses_ign_peer(env: Mapping[str, str]) -> bool:
    """Whether the Gazebo ends of a flow in ``env`` are the C++ peer on Ignition Transport 11.

    They are on ZeroMQ: a real Gazebo library, publishing at the cost a simulator pays. Zenoh
    needs our Python workers (Fortress has no Zenoh backend), and ``BENCH_GZ_END=python``
    asks for them on ZeroMQ too.
    """
    return env.get("GZ_TRANSPORT_IMPLEMENTATION") != "zenoh" and env.get("BENCH_GZ_END") != "python"


@functools.cache
def gz_message_file(kind: str) -> Path:
    """The Gazebo message of ``kind``, serialized into a file for the C++ peer's kind-pub
    (written once per run: a 1080p image is 6 MB to convert)."""
    spec = KINDS[kind]
    path = ROOT / ".build" / "bench_messages" / f"{kind}.pb"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(gz_message(spec).SerializeToString())
    return path


@dataclass(frozen=True)
class Flood:
    """A second stream that a flow's publisher process sends beside its own, from ``lead``
    seconds before the flow's first message until just after its last, to a subscriber of its
    own (``hz`` 0: back to back): through the bridge like the flow, or with ``bypass`` straight
    to a subscriber on the publisher's side (the bridge then never sees it). An ``apart`` flood
    comes from a Gazebo publisher process of its own, to a Gazebo subscriber: the same load on
    the machine beside a flow whose publisher is not that process (an rclpy one)."""

    kind: str
    topic: str
    hz: float = 0.0
    lead: float = 3.0
    bypass: bool = False
    apart: bool = False

    def subscriber(self, flow: Flow) -> str:
        """The role of the flood's subscriber."""
        if self.apart:
            return "gz-sub"
        if not self.bypass:
            return flow.subscriber
        return "gz-sub" if flow.publisher == "gz-pub" else "ros-sub"


def flood_options(flood: Flood | None, ign_peer: bool) -> list[str]:
    """The publisher options of ``flood``: the C++ peer's (``testing/peer/flood.hh``), or the
    Python workers'."""
    if flood is None:
        return []
    rate = ["--flood", flood.topic, "--flood-hz", str(flood.hz), "--flood-lead", str(flood.lead)]
    if not ign_peer:
        return [*rate, "--flood-kind", flood.kind]
    spec = KINDS[flood.kind]
    return [
        *rate,
        *("--flood-type", spec.ignition_type, "--flood-file", str(gz_message_file(flood.kind))),
        *("--flood-stamp", spec.gz_stamp_path, "--flood-wire-type", spec.gz_type),
    ]


def worker(
    role: str, topic: str, kind: str, seconds: float, env: Mapping[str, str], *extra: str
) -> PeerProcess:
    """A publisher or subscriber process of ``role`` (see ``benchmarks.workers``)."""
    if role in {"gz-pub", "gz-sub"} and uses_ign_peer(env):
        return ign_worker(role, topic, kind, seconds, env, *extra)
    command = [sys.executable, "-m", "benchmarks.workers", role, topic, kind, str(seconds)]
    return start_process([*command, *extra], env)


def ign_worker(
    role: str, topic: str, kind: str, seconds: float, env: Mapping[str, str], *extra: str
) -> PeerProcess:
    """The C++ peer's kind-pub / kind-sub as a worker: the same lines, the same STATS."""
    spec = KINDS[kind]
    if "--slow-ms" in extra:
        msg = "the C++ Gazebo subscriber has no --slow-ms"
        raise ValueError(msg)
    if role == "gz-pub":
        mode = ["kind-pub", topic, spec.ignition_type, str(gz_message_file(kind)), str(seconds)]
        mode += ["--wait", str(MATCH_WAIT), "--settle", str(PUBLISH_SETTLE)]
    else:
        mode = ["kind-sub", topic, spec.ignition_type, str(seconds)]
    options = ["--stamp", spec.gz_stamp_path, "--wire-type", spec.gz_type]
    return start_process([str(peer_binary()), *mode, *options, *extra], env)


def bridge_config(channels: Sequence[tuple[str, str, str]], queue: int) -> list[str]:
    """Bridge arguments for a YAML config of ``(topic, kind, "gz2ros" | "ros2gz")`` channels
    whose ``publisher_queue`` and ``subscriber_queue`` are ``queue``."""
    entries = []
    for topic, kind, direction in channels:
        spec = KINDS[kind]
        entries.append(
            f"- ros_topic_name: {topic}\n  gz_topic_name: {topic}\n"
            f"  ros_type_name: {spec.ros_type}\n  gz_type_name: {spec.gz_type}\n"
            f"  direction: {'GZ_TO_ROS' if direction == 'gz2ros' else 'ROS_TO_GZ'}\n"
            f"  publisher_queue: {queue}\n  subscriber_queue: {queue}\n"
        )
    path = ROOT / ".build" / "bench_configs" / f"{uuid.uuid4().hex[:8]}.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(entries), encoding="utf-8")
    return ["--ros-args", "-p", f"config_file:={path}"]


def bridge_argument(ros_topic: str, kind: str, direction: str) -> str:
    """``topic@ros_type[gz_type`` (``direction`` "gz2ros") or ``]`` ("ros2gz")."""
    spec = KINDS[kind]
    mark = "[" if direction == "gz2ros" else "]"
    return f"{ros_topic}@{spec.ros_type}{mark}{spec.gz_type}"


def start_bridge(
    arguments: Sequence[str],
    env: Mapping[str, str],
    executable: str = "parameter_bridge",
    channels: int | None = None,
) -> PeerProcess:
    """Start a bridge executable and wait until it created all its channels (one per
    argument unless ``channels`` says how many)."""
    bridge = start_process([str(BIN / executable), *arguments], env)
    if executable == "parameter_bridge":
        for _ in range(len(arguments) if channels is None else channels):
            wait_for_line(bridge, r"Creating (GZ->ROS|ROS->GZ)", 30)
    else:
        time.sleep(3)
    return bridge


@dataclass(frozen=True)
class FlowResult:
    """What the subscriber of one flow measured, plus the CPU shares (% of one core) of the
    bridge and of the end processes over the publishing window."""

    sent: int
    received: int
    rate: float
    median_us: float
    p99_us: float
    cpu: float | None
    error: str = ""
    pub_cpu: float | None = None
    sub_cpu: float | None = None
    #: What the flood's own subscriber measured (flows with a :class:`Flood`).
    flood: FlowResult | None = None
    #: The bridge's CPU share by thread group (:data:`THREAD_GROUPS`), where measured.
    bridge_threads: dict[str, float] | None = None

    @property
    def share(self) -> float:
        return self.received / self.sent if self.sent else 0.0


def failed(error: BaseException) -> FlowResult:
    first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    return FlowResult(0, 0, 0.0, 0.0, 0.0, None, first[:160])


@dataclass(frozen=True)
class Flow:
    """One publisher -> (bridge) -> subscriber run."""

    publisher: str  # ros-pub | gz-pub
    subscriber: str  # ros-sub | gz-sub
    kind: str
    seconds: float
    hz: float = 0.0
    slow_ms: float = 0.0
    #: History depth of the ROS end, publisher or subscriber (None: the bridge's default, 10).
    depth: int | None = None
    #: A named QoS profile of the ROS subscriber (``ros.qos.NAMED_PROFILES``; None: default).
    qos_profile: str | None = None
    #: A second stream from the same publisher process (see :class:`Flood`).
    flood: Flood | None = None
    #: The ROS subscriber takes the messages serialized (``workers.ros_sub``'s ``raw``).
    raw: bool = False


def run_flow(
    flow: Flow,
    topic: str,
    env: Mapping[str, str],
    *,
    pub_env: Mapping[str, str] | None = None,
    bridge_pid: int | None = None,
    during: Callable[[], None] | None = None,
) -> FlowResult:
    """Run ``flow`` on ``topic`` (``env``: the subscribers', and the publisher's unless
    ``pub_env`` is given). With a bridge in between (``bridge_pid``) the subscriber first waits
    to see the bridge's publisher. ``during`` runs once publishing started (RSS sampling)."""
    pub_env = dict(pub_env or env)
    flood = flow.flood
    #: The flood the flow's own publisher sends (an ``apart`` one has a process of its own).
    own = None if flood is None or flood.apart else flood
    if flow.publisher == "gz-pub" and LARGE_KINDS & {flow.kind, own.kind if own else ""}:
        pub_env |= _large_hwm()
    extra: tuple[str, ...] = ("--slow-ms", str(flow.slow_ms)) if flow.slow_ms else ()
    depth = () if flow.depth is None else ("--depth", str(flow.depth))
    if flow.qos_profile is not None:
        extra += ("--qos-profile", flow.qos_profile)
    sub_extra = (*extra, *depth) if flow.subscriber == "ros-sub" else extra
    if flow.raw and flow.subscriber == "ros-sub":
        sub_extra += ("--raw",)
    pub_extra = ("--hz", str(flow.hz), *(depth if flow.publisher == "ros-pub" else ()))
    pub_extra += tuple(flood_options(own, flow.publisher == "gz-pub" and uses_ign_peer(pub_env)))
    lead = 0.0 if own is None else own.lead + MATCH_WAIT
    ends: list[PeerProcess] = []
    try:
        flood_sub = flooder = None
        if flood is not None:
            role = flood.subscriber(flow)
            beside = flood.bypass or flood.apart
            flood_sub = _subscriber(
                flow, role, flood.topic, flood.kind, env=pub_env if beside else env,
                extra=(), bridge_pid=None if beside else bridge_pid,
            )  # fmt: skip
            ends.append(flood_sub)
            if flood.apart:
                flooder = _flooder(flood, flow.seconds, pub_env)
                ends.append(flooder)
        sub = _subscriber(
            flow, flow.subscriber, topic, flow.kind, env=env, extra=sub_extra, bridge_pid=bridge_pid
        )
        ends.append(sub)
        if bridge_pid is not None:
            time.sleep(SETTLE_ROS if flow.subscriber == "ros-sub" else SETTLE)
        pub = worker(flow.publisher, topic, flow.kind, flow.seconds, pub_env, *pub_extra)
        ends.append(pub)
        wait_for_line(pub, r"^CONNECTED$", 40)
        wait_for_line(pub, r"^START$", 10 + lead)
        windows = [CpuWindow(bridge_pid, by_thread=True), CpuWindow(pub.pid), CpuWindow(sub.pid)]
        for window in windows:
            window.begin()
        if during is not None:
            during()
        sent = int(wait_for_line(pub, r"^SENT (\d+)", flow.seconds + 30)[1])
        for window in windows:
            window.end()
        time.sleep(1.0)  # the last messages drain
        stats = _stats(sub)
        flooded = None
        if flood_sub is not None:
            flooded = _result(_flood_sent(pub, flooder), _stats(flood_sub))
    except FlowFailure as error:
        return failed(error)
    finally:
        for end in ends:
            end.stop()
    cpu, pub_cpu, sub_cpu = (window.percent for window in windows)
    return dataclasses.replace(
        _result(sent, stats, cpu),
        pub_cpu=pub_cpu,
        sub_cpu=sub_cpu,
        flood=flooded,
        bridge_threads=windows[0].groups,
    )


def _large_hwm() -> dict[str, str]:
    """The send queue of a Gazebo publisher of large messages: ``transport.LARGE_HWM``, the
    transport benchmark's bound."""
    return {f"{prefix}TRANSPORT_SNDHWM": str(LARGE_HWM) for prefix in ("GZ_", "IGN_")}


def _flooder(flood: Flood, seconds: float, env: Mapping[str, str]) -> PeerProcess:
    """The Gazebo process of an ``apart`` flood, sending back to back to its subscriber since
    ``flood.lead`` seconds; it runs until stopped (its SENT line then counts the frames)."""
    spare = 60.0  # the flow's own start-up: stopped as soon as the flow has sent
    flooder = worker(
        "gz-pub", flood.topic, flood.kind, seconds + spare, {**env, **_large_hwm()},
        "--hz", str(flood.hz),
    )  # fmt: skip
    wait_for_line(flooder, r"^START$", 40)
    time.sleep(flood.lead)
    return flooder


def _flood_sent(pub: PeerProcess, flooder: PeerProcess | None) -> int:
    """How many flood messages were sent: by the flow's publisher, or by the flood's own
    process (stopped here)."""
    if flooder is None:
        return int(wait_for_line(pub, r"^FLOOD_SENT (\d+)", 10)[1])
    flooder.stop()
    return int(wait_for_line(flooder, r"^SENT (\d+)", 10)[1])


def _subscriber(
    flow: Flow,
    role: str,
    topic: str,
    kind: str,
    *,
    env: Mapping[str, str],
    extra: Sequence[str],
    bridge_pid: int | None,
) -> PeerProcess:
    """A started subscriber of ``flow``, ready (and matched to the bridge, if any)."""
    lead = 0.0 if flow.flood is None else flow.flood.lead
    sub = worker(role, topic, kind, flow.seconds + lead + 60, env, *extra)
    wait_for_line(sub, r"^READY$", 30)
    if bridge_pid is not None:
        wait_for_line(sub, r"^MATCHED$", 20)
    return sub


def _stats(sub: PeerProcess) -> re.Match[str]:
    """The STATS line ``sub`` prints when stopped."""
    sub.stop(grace=15)
    return wait_for_line(sub, STATS_LINE.pattern, 5)


def _result(sent: int, stats: re.Match[str], cpu: float | None = None) -> FlowResult:
    return FlowResult(sent, int(stats[1]), float(stats[4]), float(stats[5]), float(stats[6]), cpu)


def stop_all() -> None:
    """Stop every process the benchmarks started, and remove the Fast DDS shared-memory
    segments that stopped rclpy processes left behind (a worker that ends with ``os._exit``
    never closes its participant: an hour of benchmarks left 123 segments, 3.2 GB of
    /dev/shm, which later runs then paid for in memory pressure)."""
    stop_processes(grace=3)
    remove_zombie_segments()
