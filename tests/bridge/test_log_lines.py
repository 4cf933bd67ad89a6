"""The creation lines of a real ``parameter_bridge``: the C++ bridge's text, word for word.

One bridge process in the namespace ``/logs`` creates, from its command line, a topic each
way, a bidirectional one, one with a relative name and two services (with and without their
Gazebo types), and from a YAML file a lazy topic each way. No Gazebo is needed: the lines are
logged when the bridges are created.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from testing.behaviour_harness import WAIT, relative, start_bridge
from testing.gzpeer import PeerProcess, unique_name, wait_until

pytestmark = [pytest.mark.ros]

STRING = "std_msgs/msg/String"
CONTROL_WORLD = "ros_gz_interfaces/srv/ControlWorld"
NAMESPACE = "/logs"
#: What the bridge node logs at INFO: ``[INFO] [<time>] [logs.ros_gz_bridge]: <text>``.
_INFO = re.compile(r"^\[INFO\] \[[0-9.]+\] \[logs\.ros_gz_bridge\]: (.*)$")


class Bridge:
    """The running bridge and the names it was given."""

    def __init__(self, folder: Path) -> None:
        self.names = {
            key: unique_name(f"log_{key}")
            for key in ("g2r", "r2g", "both", "lazy_g2r", "lazy_r2g", "svc", "svc_typed")
        }
        self.names["rel"] = relative(unique_name("log_rel"))
        names = self.names
        config = folder / "lazy.yaml"
        config.write_text(
            "".join(
                f"- topic_name: {names[key]}\n  ros_type_name: {STRING}\n"
                f"  gz_type_name: gz.msgs.StringMsg\n  direction: {direction}\n  lazy: true\n"
                for key, direction in (("lazy_g2r", "GZ_TO_ROS"), ("lazy_r2g", "ROS_TO_GZ"))
            )
        )
        self.process: PeerProcess = start_bridge(
            f"{names['g2r']}@{STRING}[ignition.msgs.StringMsg",
            f"{names['r2g']}@{STRING}]gz.msgs.StringMsg",
            f"{names['both']}@{STRING}@gz.msgs.StringMsg",
            f"{names['rel']}@{STRING}]gz.msgs.StringMsg",
            f"{names['svc']}@{CONTROL_WORLD}",
            f"{names['svc_typed']}@{CONTROL_WORLD}@gz.msgs.WorldControl@gz.msgs.Boolean",
            ros_args=["-r", f"__ns:={NAMESPACE}", "-p", f"config_file:={config}"],
        )

    def texts(self) -> list[str]:
        """What the bridge node logged at INFO so far, in order."""
        lines = self.process.output().splitlines()
        return [m.group(1) for line in lines if (m := _INFO.match(line))]

    def wait_for(self, *expected: str) -> list[str]:
        """Wait until every ``expected`` text was logged; returns everything logged then."""
        wait_until(
            lambda: all(text in self.texts() for text in expected),
            WAIT,
            f"the log lines {list(expected)}; output:\n{self.process.output()}",
        )
        return self.texts()


@pytest.fixture(scope="module")
def bridge(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Bridge]:
    running = Bridge(tmp_path_factory.mktemp("log_lines"))
    yield running
    running.process.stop()


def gz_to_ros(topic: str, gz_type: str, lazy: int) -> str:
    return f"Creating GZ->ROS Bridge: [{topic} ({gz_type}) -> {topic} ({STRING})] (Lazy {lazy})"


def ros_to_gz(topic: str, gz_type: str, lazy: int) -> str:
    return f"Creating ROS->GZ Bridge: [{topic} ({STRING}) -> {topic} ({gz_type})] (Lazy {lazy})"


def test_each_way_logs_the_cpp_line_lazy_and_not(bridge: Bridge) -> None:
    names = bridge.names
    texts = bridge.wait_for(
        gz_to_ros(names["g2r"], "ignition.msgs.StringMsg", 0),
        ros_to_gz(names["r2g"], "gz.msgs.StringMsg", 0),
        gz_to_ros(names["lazy_g2r"], "gz.msgs.StringMsg", 1),
        ros_to_gz(names["lazy_r2g"], "gz.msgs.StringMsg", 1),
    )
    for key in ("g2r", "r2g", "lazy_g2r", "lazy_r2g"):  # absolute names: no line of ours
        assert not [text for text in texts if text.endswith(f"resolves to {names[key]}")]


def test_a_bidirectional_bridge_logs_gazebo_to_ros_then_ros_to_gz(bridge: Bridge) -> None:
    topic = bridge.names["both"]
    first = gz_to_ros(topic, "gz.msgs.StringMsg", 0)
    second = ros_to_gz(topic, "gz.msgs.StringMsg", 0)
    texts = bridge.wait_for(first, second)
    assert texts.index(second) == texts.index(first) + 1


def test_a_relative_name_is_logged_as_given_then_resolved(bridge: Bridge) -> None:
    topic = bridge.names["rel"]
    resolved = f"{NAMESPACE}/{topic}"
    creating = ros_to_gz(topic, "gz.msgs.StringMsg", 0)
    ours = (
        f"ROS->GZ [{resolved} ({STRING}) -> {topic} (gz.msgs.StringMsg)]: "
        f"the ROS name {topic} resolves to {resolved}"
    )
    texts = bridge.wait_for(creating, ours)
    assert texts.index(ours) == texts.index(creating) + 1


def test_services_log_the_cpp_line_with_the_types_as_given(bridge: Bridge) -> None:
    service, typed = bridge.names["svc"], bridge.names["svc_typed"]
    creating = f"Creating ROS->GZ service bridge [{service} ({CONTROL_WORLD} -> /)]"
    ours = (
        f"ROS->GZ service [{service} ({CONTROL_WORLD} -> gz.msgs.WorldControl/gz.msgs.Boolean)]: "
        "the Gazebo types left out are the service type's"
    )
    creating_typed = (
        f"Creating ROS->GZ service bridge [{typed} ({CONTROL_WORLD} -> "
        "gz.msgs.WorldControl/gz.msgs.Boolean)]"
    )
    texts = bridge.wait_for(creating, ours, creating_typed)
    assert texts.index(ours) == texts.index(creating) + 1
    assert not [text for text in texts if text.startswith(f"ROS->GZ service [{typed} ")]
