"""``python -m ros_gz_bridge_py.demo`` (``make demo``): the bridge at work, no Gazebo needed.

Starts the Python world (the Gazebo side), ``parameter_bridge`` with the TurtleBot3 Waffle
configuration, an image bridge for the camera, and runs the ROS client in this process. It
stops on Ctrl-C or after ``DEMO_SECONDS`` of live table (0 or unset: until Ctrl-C), stops every
child, and prints a summary with a PASS/FAIL line. Exit status: 0 on PASS, 1 on FAIL, 2 on a bad
``DEMO_SECONDS`` or an argument (it takes none but ``-h``).
"""

from __future__ import annotations

import os
import signal
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ros_gz_bridge_py.demo import topics
from ros_gz_bridge_py.demo.client import NODE_NAME, DemoClient, wait_for_bridge, watch
from ros_gz_bridge_py.demo.processes import Child
from ros_gz_bridge_py.demo.report import Pose2D, Row, format_rows, verdict
from ros_gz_bridge_py.errors import BridgeError

WORLD_START_TIMEOUT = 20.0
BRIDGE_START_TIMEOUT = 30.0
LOG_TAIL_LINES = 15
#: Applied when the environment has none of its own, so the demo never leaves this host.
LOOPBACK_DEFAULTS = {
    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
    "GZ_IP": "127.0.0.1",
    "IGN_IP": "127.0.0.1",
}


class DemoSetupError(BridgeError):
    """The demo cannot start (bad DEMO_SECONDS, missing configuration or executable)."""


def demo_seconds() -> float:
    """DEMO_SECONDS as a number of seconds (0 = until Ctrl-C)."""
    text = os.environ.get("DEMO_SECONDS", "0").strip() or "0"
    try:
        seconds = float(text)
    except ValueError:
        seconds = -1.0
    if not seconds >= 0:
        msg = f"DEMO_SECONDS={text!r} is not a number of seconds >= 0 (0 runs until Ctrl-C)"
        raise DemoSetupError(msg)
    return seconds


def prepare_environment() -> list[str]:
    """Loopback defaults and a partition of our own where unset; the settings applied."""
    applied = []
    for name, value in LOOPBACK_DEFAULTS.items():
        if name not in os.environ:
            os.environ[name] = value
            applied.append(f"{name}={value}")
    if "GZ_PARTITION" not in os.environ and "IGN_PARTITION" not in os.environ:
        partition = f"ros_gz_bridge_demo_{os.getpid()}"
        os.environ["GZ_PARTITION"] = os.environ["IGN_PARTITION"] = partition
        applied.append(f"GZ_PARTITION={partition}")
    return applied


@dataclass(frozen=True)
class BridgeCommand:
    """A bridge process to start: its name, command line and environment additions."""

    name: str
    command: list[str]
    env: dict[str, str]


def bridge_commands() -> list[BridgeCommand]:
    """parameter_bridge with the TurtleBot3 configuration, and image_bridge for the camera."""
    if not topics.CONFIG_FILE.is_file():
        msg = (
            f"the bridge configuration {topics.CONFIG_FILE} is missing; run the demo from the "
            "source tree or reinstall the package (it installs the file there)"
        )
        raise DemoSetupError(msg)
    executable = Path(sys.executable).with_name("parameter_bridge")
    if not executable.exists():
        msg = f"{executable} is missing; run `make setup-demo` (pip install -e .)"
        raise DemoSetupError(msg)
    parameter_bridge = [str(executable), "--ros-args", "-p", f"config_file:={topics.CONFIG_FILE}"]
    image_bridge = [sys.executable, "-m", "ros_gz_bridge_py.app.image_bridge", topics.CAMERA_IMAGE]
    return [
        BridgeCommand("bridge", parameter_bridge, {}),
        BridgeCommand("image bridge", image_bridge, {}),
    ]


class StopFlag:
    """Set by SIGINT/SIGTERM; the main loop polls it."""

    def __init__(self) -> None:
        self.reason: str | None = None
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._handle)

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        self.reason = f"stopped by {signal.Signals(signum).name}"


def stop_check(
    flag: StopFlag, children: list[Child], deadline: float | None
) -> Callable[[], str | None]:
    """Why the demo should stop now: a signal, the deadline, or a child that exited."""

    def check() -> str | None:
        if flag.reason is not None:
            return flag.reason
        for child in children:
            status = child.exited()
            if status is not None:
                return f"the {child.name} exited with status {status}"
        if deadline is not None and time.monotonic() >= deadline:
            return "DEMO_SECONDS elapsed"
        return None

    return check


def print_intro(children: list[Child], seconds: float, applied: list[str], log_dir: Path) -> None:
    print("ros_gz_bridge_py demo: a TurtleBot3-like robot in a Python Gazebo world, bridged to ROS")
    print(f"  configuration  {topics.CONFIG_FILE}")
    for child in children:
        print(f"  {child.name:<13}  pid {child.pid}: {' '.join(child.command)}")
    print(
        f"  client         this process: publishes /{topics.CMD_VEL} "
        "(drive in a circle) and watches every bridged topic"
    )
    print(f"  logs           {log_dir}")
    partition = os.environ.get("GZ_PARTITION") or os.environ.get("IGN_PARTITION", "")
    print(f"  GZ_PARTITION={partition} ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID', '0')}")
    if applied:
        print(f"  set by the demo: {' '.join(applied)}")
    print("  latency = arrival wall time - message stamp (the world stamps with the wall clock)")
    until = f"for {seconds:g} s (DEMO_SECONDS)" if seconds else "until Ctrl-C"
    print(f"The live table refreshes every second {until}.", flush=True)


def print_log_tails(children: list[Child]) -> None:
    for child in children:
        tail = child.log().splitlines()[-LOG_TAIL_LINES:]
        print(f"--- last lines of the {child.name} log ({child.log_path}) ---")
        print("\n".join(tail) if tail else "(empty)")


def print_summary(outcome: Outcome) -> bool:
    """The final table, the first and last pose, and the verdict; True on PASS."""
    print(f"=== summary ({outcome.reason}; watched for {outcome.watched_seconds:.1f} s) ===")
    print("\n".join(format_rows(outcome.rows)))
    print(f"robot pose (odom): first {outcome.first_pose or 'none'}")
    print(f"                   last  {outcome.last_pose or 'none'}")
    result = verdict(outcome.rows, outcome.first_pose, outcome.last_pose)
    print(result.line, flush=True)
    return result.passed


def start_children(log_dir: Path, children: list[Child], stop: StopFlag) -> str | None:
    """Start the world, then the bridges; why starting failed, or None."""
    world_command = [sys.executable, "-m", "ros_gz_bridge_py.demo.world"]
    world = Child("world", world_command, log_dir / "world.log", {})
    children.append(world)
    if not world.wait_for_output("READY", WORLD_START_TIMEOUT, lambda: stop.reason is not None):
        return f"the world did not start within {WORLD_START_TIMEOUT:g} s"
    for bridge in bridge_commands():
        log_path = log_dir / f"{bridge.name.replace(' ', '_')}.log"
        children.append(Child(bridge.name, bridge.command, log_path, bridge.env))
    return stop.reason


def run(seconds: float, applied: list[str]) -> bool:
    """The whole demo; True on PASS."""
    stop = StopFlag()
    log_dir = Path(tempfile.mkdtemp(prefix="ros_gz_bridge_demo-"))
    children: list[Child] = []
    try:
        failure = start_children(log_dir, children, stop)
        print_intro(children, seconds, applied, log_dir)
        if failure is not None:
            print(f"FAIL: {failure}")
            print_log_tails(children)
            return False
        outcome = watch_with_ros(children, stop, seconds)
    finally:
        for child in reversed(children):
            child.stop()
    passed = print_summary(outcome)
    if not passed:
        print_log_tails(children)
    return passed


@dataclass(frozen=True)
class Outcome:
    """What the client saw: overall rows, first and last odometry pose, why it stopped."""

    rows: list[Row]
    first_pose: Pose2D | None
    last_pose: Pose2D | None
    reason: str
    watched_seconds: float


def watch_with_ros(children: list[Child], stop: StopFlag, seconds: float) -> Outcome:
    """Run the ROS client until a stop reason (``seconds`` of live table, 0 = no limit)."""
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = Node(NODE_NAME)
        client = DemoClient(node)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        missing = wait_for_bridge(
            client, executor, BRIDGE_START_TIMEOUT, stop_check(stop, children, None)
        )
        if missing:
            print(f"still no bridge endpoint for {', '.join(missing)}; watching anyway")
        started = time.monotonic()
        deadline = started + seconds if seconds else None
        reason = watch(client, executor, stop_check(stop, children, deadline))
        outcome = Outcome(
            rows=[stats.overall() for stats in client.stats.values()],
            first_pose=client.first_pose,
            last_pose=client.pose,
            reason=reason,
            watched_seconds=time.monotonic() - started,
        )
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.try_shutdown()
    return outcome


def main(argv: Sequence[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    if args in (["-h"], ["--help"]):
        print(__doc__)
        return 0
    if args:
        print(f"demo: takes no arguments, not {' '.join(args)!r} (-h tells more)", file=sys.stderr)
        return 2
    try:
        seconds = demo_seconds()
    except DemoSetupError as err:
        print(f"demo: {err}", file=sys.stderr)
        return 2
    applied = prepare_environment()
    try:
        passed = run(seconds, applied)
    except DemoSetupError as err:
        print(f"demo: {err}", file=sys.stderr)
        return 1
    return 0 if passed else 1


if __name__ == "__main__":
    raise SystemExit(main())
