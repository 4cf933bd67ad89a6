"""``parameter_bridge --check`` on an in-memory Gazebo network and a real rclpy node: entries
with names a side refuses, the "similar topics" hint, and a stop request (the real executable
is run in tests/bridge/test_explanations.py and tests/bridge/test_check_signals.py)."""

from __future__ import annotations

import io
import os
import signal
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from ros_gz_bridge_py.app.check import STOPPED, Sides, run_check
from ros_gz_bridge_py.config import BridgeSpec, Direction, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode

pytestmark = [pytest.mark.ros]

STRING, ROS_STRING = "gz.msgs.StringMsg", "std_msgs/msg/String"
#: Seconds a check listens here: the in-memory network shows everything at once.
LISTEN = 0.2


@pytest.fixture
def sides(ros_context: Any, network: MemoryNetwork) -> Iterator[Sides]:
    import rclpy  # noqa: PLC0415 - rclpy is loaded by the tests that need it only

    node = rclpy.create_node("check_test", context=ros_context)
    try:
        yield Sides(node, MemoryGzNode(network=network), default_registry())
    finally:
        node.destroy_node()


def sleep_a_step(timeout_sec: float) -> None:
    """The ROS spinning of the check: nothing to spin here."""
    time.sleep(timeout_sec)


def check(
    sides: Sides, specs: list[BridgeSpec], seconds: float = LISTEN, stop: StopSignal | None = None
) -> tuple[int, str]:
    out = io.StringIO()
    status = run_check(sides, specs, seconds, out=out, spin_once=sleep_a_step, stop=stop)
    return status, out.getvalue()


def topic(ros: str, gz: str, direction: Direction) -> TopicBridgeSpec:
    return TopicBridgeSpec(ros, gz, ROS_STRING, STRING, direction)


def test_entries_with_refused_names_get_a_problem_and_the_others_their_report(
    sides: Sides, network: MemoryNetwork
) -> None:
    MemoryGzNode(network=network).advertise("/ok", STRING)
    status, out = check(
        sides,
        [
            topic("/a//b", "/a/b", Direction.GZ_TO_ROS),
            topic("priv", "~/priv", Direction.ROS_TO_GZ),
            topic("/ok", "/ok", Direction.GZ_TO_ROS),
        ],
    )
    assert status == 1, out
    assert (
        "/a//b <-> /a/b\n  PROBLEM: invalid ROS topic name '/a//b': failed to resolve name: "
        "topic name must not contain repeated '/'; [/a//b] is no valid ROS name: a ROS name is "
        "letters, digits and underscores between its '/' (no '-', '.' or spaces)\n"
    ) in out
    assert "priv <-> ~/priv\n  PROBLEM: invalid Gazebo Transport topic '~/priv'" in out
    assert "-p expand_gz_topic_names:=true expands '~'" in out
    assert out.count("cannot announce ~/priv") == 1  # not again when listening is half done
    assert "Gazebo /ok (gz.msgs.StringMsg) -> ROS /ok (std_msgs/msg/String)\n" in out
    assert out.endswith("1 of 3 checked can carry messages; 2 cannot (see PROBLEM lines)\n")


def test_similar_topics_are_other_processes_never_the_checks_own(
    sides: Sides, network: MemoryNetwork
) -> None:
    other = MemoryGzNode(network=network)
    other.advertise("/model/r2/odometry", STRING)
    other.subscribe("/model/r2/cmd_vel", lambda *_: None, STRING)
    _, out = check(
        sides,
        [
            topic("/model/r1/odometry", "/model/r1/odometry", Direction.GZ_TO_ROS),
            topic("/model/r1/cmd_vel", "/model/r1/cmd_vel", Direction.ROS_TO_GZ),
        ],
    )
    hints = [line for line in out.splitlines() if " there: " in line]
    assert len(hints) == 2, out
    # A Gazebo->ROS entry is shown publishers, a ROS->Gazebo one subscribers (it was shown
    # publishers, which a ROS->Gazebo entry cannot use), of its type first.
    assert hints[0].endswith("Gazebo publishers of gz.msgs.StringMsg there: /model/r2/odometry")
    assert hints[1].endswith("Gazebo subscribers of gz.msgs.StringMsg there: /model/r2/cmd_vel")


def test_sigint_ends_the_check_at_once_without_a_report(sides: Sides) -> None:
    specs: list[BridgeSpec] = [topic("/x", "/x", Direction.BIDIRECTIONAL)]
    interrupt = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    with StopSignal() as stop:  # the executable's
        started = time.monotonic()
        interrupt.start()
        status, out = check(sides, specs, seconds=30.0, stop=stop)
        took = time.monotonic() - started
        interrupt.join()
    assert (status, out.splitlines()[-1]) == (0, STOPPED)
    assert took < 15.0  # not the 30 s asked for
    assert "checked can carry messages" not in out


@pytest.mark.parametrize("overridden", [False, True])
def test_the_qos_overrides_given_are_those_the_check_compares(
    ros_context: Any, network: MemoryNetwork, overridden: bool
) -> None:
    """--check compared the profile without the overrides: a transient-local subscriber the
    override serves was a PROBLEM, and the check failed, while the bridge carried it."""
    import rclpy  # noqa: PLC0415
    from rclpy.parameter import Parameter  # noqa: PLC0415
    from rclpy.qos import DurabilityPolicy, QoSProfile  # noqa: PLC0415
    from std_msgs.msg import String  # noqa: PLC0415

    name = f"/latched_{os.getpid()}_{int(overridden)}"
    override = Parameter(f"qos_overrides.{name}.publisher.durability", value="transient_local")
    node = rclpy.create_node(
        "check_qos", context=ros_context, parameter_overrides=[override] if overridden else []
    )
    listener = rclpy.create_node("check_qos_listener", context=ros_context)
    try:
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        listener.create_subscription(String, name, lambda _m: None, latched)
        deadline = time.monotonic() + 10
        while not node.get_subscriptions_info_by_topic(name) and time.monotonic() < deadline:
            time.sleep(0.01)
        MemoryGzNode(network=network).advertise(name, STRING)
        sides = Sides(node, MemoryGzNode(network=network), default_registry())
        status, out = check(sides, [topic(name, name, Direction.GZ_TO_ROS)])
    finally:
        listener.destroy_node()
        node.destroy_node()
    problem = "Volatile publisher and transient local subscription"
    assert (problem in out) is not overridden, out
    assert status == (0 if overridden else 1), out


def test_a_bidirectional_entry_carrying_one_way_passes(
    sides: Sides, network: MemoryNetwork
) -> None:
    """A working '@' entry (Gazebo publishes, nothing in Gazebo subscribes) failed the check:
    its ROS -> Gazebo half's 'no Gazebo subscriber' was a PROBLEM (found by a new user)."""
    name = f"/both_{os.getpid()}"
    MemoryGzNode(network=network).advertise(name, STRING)
    status, out = check(sides, [topic(name, name, Direction.BIDIRECTIONAL)])
    assert status == 0, out
    assert "PROBLEM" not in out
    assert f"waiting, while the other direction carries: no Gazebo subscriber of {name}" in out
    assert out.endswith("2 of 2 checked can carry messages\n")
    # a one-way entry with nothing on its Gazebo side is still a problem
    status, out = check(sides, [topic(f"{name}_in", f"{name}_in", Direction.ROS_TO_GZ)])
    assert status == 1, out
