"""What does the TurtleBot3 workload cost a bridge? The seed configuration unchanged, one C++
peer process per stream at the simulator's rates, one rclpy subscriber; the bridge's CPU on each
path (section 2 of ``benchmarks.native_plane``). ``python -m benchmarks.native_workload`` is that
subscriber, which the benchmark starts itself.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from benchmarks.bridged import bridge_process
from benchmarks.harness import ROOT, CpuWindow, FlowFailure, failed
from benchmarks.native_paths import (
    SPLIT,
    Counters,
    MachineWindow,
    busiest,
    counted_since,
    counters,
    cpu_cell,
    path_backend,
    thread_seconds,
    threads_cell,
)
from benchmarks.payloads import KINDS
from benchmarks.tables import verdict
from benchmarks.workers import MATCH_WAIT
from benchmarks.workers import SETTLE as PUBLISH_SETTLE
from ros_gz_bridge_py.converters.registry import Pair, default_registry
from testing.gzpeer import peer_binary, start_process, wait_for_line
from testing.run_env import run_env

#: Issue 22: the TurtleBot3 workload costs the bridge at most this % of one core.
GOAL_WORKLOAD_CPU = 15.0
TURTLEBOT_CONFIG = ROOT / "config" / "turtlebot3_waffle_bridge.yaml"
#: Channels the seed configuration makes (all of its entries).
TURTLEBOT_CHANNELS = 8
#: Seconds the workload publishes before and after the CPU window.
WORKLOAD_MARGIN = 1.0


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
    command = [sys.executable, "-m", "benchmarks.native_workload"]
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


def workload_row(run: Workload) -> str:
    if run.error or run.sent is None or run.received is None:
        return f"| {run.path} | failed: {run.error} |||||"
    sent, received, counted = run.sent, run.received, run.counted or {}
    topics = ", ".join(f"{t} {received[t]}/{sent[t]}" for t in sent)
    paths = ", ".join(f"{t} {c.path}" for t, c in counted.items()) or "-"
    return (
        f"| {run.path} | **{cpu_cell(run.cpu)}** | {threads_cell(run.threads)} | {topics} "
        f"| {paths} | {cpu_cell(run.machine)} |"
    )


WORKLOAD_HEADER = (
    f"| path | bridge CPU, % of a core | of which {SPLIT} threads | delivered/sent per "
    "topic | PATH column | machine CPU |\n|---|---|---|---|---|---|"
)


def median_run(runs: list[Workload], path: str) -> Workload | None:
    """The run of ``path`` with the median CPU (the lower middle one of an even count)."""
    measured = sorted((run for run in runs if run.path == path and run.cpu), key=_cpu_of)
    return measured[(len(measured) - 1) // 2] if measured else None


def _cpu_of(run: Workload) -> float:
    return run.cpu or 0.0


def workload_goal(runs: list[Workload]) -> str:
    native = median_run(runs, "native")
    what = f"- The TurtleBot3 workload costs the native bridge <= {GOAL_WORKLOAD_CPU:g}% of a core"
    if native is None or native.cpu is None:
        failed = next((run.error for run in runs if run.path == "native"), "no run")
        return f"{what}: not measured ({failed})"
    python = median_run(runs, "Python")
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
            f"; by thread group ({SPLIT}): {threads_cell(native.threads)}, at {rate:g} messages a "
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


if __name__ == "__main__":
    subscriber()
