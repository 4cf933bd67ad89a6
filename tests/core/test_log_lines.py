"""The lines a bridge logs on creating its channels and services, read from its real log
output (rcutils writes them to this process's stderr).

Each creation line is the C++ bridge's, word for word, with the names and types as configured
(docs/behaviour.md §5); where ROS resolution changed a name, or a service's Gazebo types were
left out, a line of ours follows it.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, ServiceBridgeSpec, TopicBridgeSpec
from ros_gz_bridge_py.core.bridge import BridgeHandle
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.msgs import message_class
from tests.core import harness
from tests.core.harness import Rig, gz_to_ros, options, ros_to_gz, unique

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING = "std_msgs/msg/String"
CONTROL_WORLD = "ros_gz_interfaces/srv/ControlWorld"
NAMESPACE = "/robot1"


@pytest.fixture
def namespaced(make_rig: Callable[..., Rig]) -> Rig:
    """A bridge whose node lives in :data:`NAMESPACE`."""
    return make_rig(node_options={"namespace": NAMESPACE})


def logged(rig: Rig, capfd: pytest.CaptureFixture[str]) -> list[str]:
    """The texts of what ``rig``'s bridge logged at INFO since the last call, in order."""
    node = rig.node
    logger = f"{node.get_namespace().strip('/')}.{node.get_name()}".lstrip(".")
    pattern = re.compile(rf"^\[INFO\] \[[0-9.]+\] \[{re.escape(logger)}\]: (.*)$")
    _, err = capfd.readouterr()
    return [m.group(1) for line in err.splitlines() if (m := pattern.match(line))]


def add(
    rig: Rig, topic: str, gz_type: str, direction: Direction, lazy: bool | None = None
) -> BridgeHandle:
    return rig.add(TopicBridgeSpec(topic, topic, STRING, gz_type, direction, lazy=lazy))


@pytest.mark.parametrize("lazy", [False, True])
def test_each_way_logs_the_cpp_line(
    rig: Rig, capfd: pytest.CaptureFixture[str], lazy: bool
) -> None:
    to_ros, to_gz = unique("log_to_ros"), unique("log_to_gz")
    add(rig, to_ros, "ignition.msgs.StringMsg", Direction.GZ_TO_ROS, lazy=lazy)
    add(rig, to_gz, "gz.msgs.StringMsg", Direction.ROS_TO_GZ, lazy=lazy)
    assert logged(rig, capfd) == [
        f"Creating GZ->ROS Bridge: [{to_ros} (ignition.msgs.StringMsg) -> {to_ros} ({STRING})] "
        f"(Lazy {int(lazy)})",
        f"Creating ROS->GZ Bridge: [{to_gz} ({STRING}) -> {to_gz} (gz.msgs.StringMsg)] "
        f"(Lazy {int(lazy)})",
    ]


def test_a_bidirectional_bridge_logs_gazebo_to_ros_first(
    rig: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    topic = unique("log_both")
    add(rig, topic, "gz.msgs.StringMsg", Direction.BIDIRECTIONAL)
    assert logged(rig, capfd) == [
        f"Creating GZ->ROS Bridge: [{topic} (gz.msgs.StringMsg) -> {topic} ({STRING})] (Lazy 0)",
        f"Creating ROS->GZ Bridge: [{topic} ({STRING}) -> {topic} (gz.msgs.StringMsg)] (Lazy 0)",
    ]


def test_the_bridge_wide_lazy_setting_shows_as_lazy_1(
    make_rig: Callable[..., Rig], capfd: pytest.CaptureFixture[str]
) -> None:
    rig = make_rig(options(lazy=True))
    topic = unique("log_lazy")
    add(rig, topic, "gz.msgs.StringMsg", Direction.GZ_TO_ROS)
    assert logged(rig, capfd) == [
        f"Creating GZ->ROS Bridge: [{topic} (gz.msgs.StringMsg) -> {topic} ({STRING})] (Lazy 1)"
    ]


def test_a_relative_name_is_logged_as_given_then_resolved(
    namespaced: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    topic = unique("log_rel").lstrip("/")
    handle = add(namespaced, topic, "gz.msgs.StringMsg", Direction.BIDIRECTIONAL)
    resolved = f"{NAMESPACE}/{topic}"
    to_ros, to_gz = gz_to_ros(handle), ros_to_gz(handle)
    assert to_ros.describe() == f"GZ->ROS [{topic} (gz.msgs.StringMsg) -> {resolved} ({STRING})]"
    assert to_gz.describe() == f"ROS->GZ [{resolved} ({STRING}) -> {topic} (gz.msgs.StringMsg)]"
    assert logged(namespaced, capfd) == [
        f"Creating GZ->ROS Bridge: [{topic} (gz.msgs.StringMsg) -> {topic} ({STRING})] (Lazy 0)",
        f"{to_ros.describe()}: the ROS name {topic} resolves to {resolved}",
        f"Creating ROS->GZ Bridge: [{topic} ({STRING}) -> {topic} (gz.msgs.StringMsg)] (Lazy 0)",
        f"{to_gz.describe()}: the ROS name {topic} resolves to {resolved}",
    ]


def test_a_relative_name_in_the_root_namespace_gets_no_extra_line(
    rig: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    topic = unique("log_root").lstrip("/")
    add(rig, topic, "gz.msgs.StringMsg", Direction.GZ_TO_ROS)
    assert logged(rig, capfd) == [
        f"Creating GZ->ROS Bridge: [{topic} (gz.msgs.StringMsg) -> {topic} ({STRING})] (Lazy 0)"
    ]


def test_a_service_with_its_gazebo_types_logs_the_cpp_line(
    rig: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    service = unique("log_svc")
    rig.add(
        ServiceBridgeSpec(service, CONTROL_WORLD, "ignition.msgs.WorldControl", "gz.msgs.Boolean")
    )
    assert logged(rig, capfd) == [
        f"Creating ROS->GZ service bridge [{service} ({CONTROL_WORLD} -> "
        "ignition.msgs.WorldControl/gz.msgs.Boolean)]"
    ]


def test_a_service_without_gazebo_types_logs_them_empty_then_ours(
    namespaced: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    service = unique("log_svc_rel").lstrip("/")
    handle = namespaced.add(ServiceBridgeSpec(service, CONTROL_WORLD))
    assert handle.service is not None
    described = handle.service.describe()
    assert described == (
        f"ROS->GZ service [{NAMESPACE}/{service} ({CONTROL_WORLD} -> "
        "gz.msgs.WorldControl/gz.msgs.Boolean)]"
    )
    assert logged(namespaced, capfd) == [
        f"Creating ROS->GZ service bridge [{service} ({CONTROL_WORLD} -> /)]",
        f"{described}: the ROS name {service} resolves to {NAMESPACE}/{service}; "
        "the Gazebo types left out are the service type's",
    ]


def test_an_entry_a_side_refuses_is_not_logged_as_created(
    rig: Rig, capfd: pytest.CaptureFixture[str]
) -> None:
    """The bridge made its channels' creation lines before it started them: a Gazebo name the
    transport refuses was logged as "Creating ..." and then refused."""
    logged(rig, capfd)
    with pytest.raises(ConfigError, match="invalid Gazebo Transport topic"):
        rig.add(TopicBridgeSpec(unique("ros_ok"), "/my topic", STRING, "gz.msgs.StringMsg"))
    assert logged(rig, capfd) == []


def test_passing_a_message_to_gazebo_is_logged_once_per_pair_of_types(
    rig: Rig, world: harness.RosWorld, capfd: pytest.CaptureFixture[str]
) -> None:
    """Each channel logged it ("showing msg only once per type" twice, for two topics)."""
    for topic in (unique("log_pass_a"), unique("log_pass_b")):
        add(rig, topic, "gz.msgs.StringMsg", Direction.ROS_TO_GZ)
        inbox = harness.Inbox()
        rig.gazebo().subscribe_typed(topic, message_class("gz.msgs.StringMsg"), inbox)
        publisher = world.publisher(String, topic)

        def publish(i: int, publisher: Any = publisher) -> None:
            publisher.publish(String(data=str(i)))

        def arrived(inbox: harness.Inbox = inbox) -> bool:
            return bool(inbox.messages())

        harness.publish_until(publish, arrived, "a message in Gazebo")
    passing = [line for line in logged(rig, capfd) if line.startswith("Passing message")]
    assert passing == [
        f"Passing message from ROS {STRING} to Gazebo gz.msgs.StringMsg (showing msg only once "
        "per type)"
    ]
