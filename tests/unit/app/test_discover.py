"""``parameter_bridge --discover``: its argument, its listening's end at SIGINT, and the YAML it
writes reads back as the same bridges (the end-to-end run is in
tests/bridge/test_discovered_e2e.py)."""

from __future__ import annotations

import io
import os
import signal
import threading
import time

import pytest

from ros_gz_bridge_py.app.discover import header_lines, listen, write_yaml
from ros_gz_bridge_py.app.parameter_bridge import DISCOVER_OPTION, split_seconds_option
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec, UsageError, parse_yaml
from ros_gz_bridge_py.core.discovery_plan import AUTO_SOURCE, BY_ROS_PUBLISHER
from ros_gz_bridge_py.ros.stop_signal import StopSignal

SPECS = [
    TopicBridgeSpec(
        "clock", "/clock", "rosgraph_msgs/msg/Clock", "ignition.msgs.Clock",
        Direction.GZ_TO_ROS, lazy=True,
    ),
    TopicBridgeSpec(
        "model/r_1/cmd_vel", "/model/r-1/cmd_vel", "geometry_msgs/msg/Twist", "gz.msgs.Twist",
        Direction.ROS_TO_GZ, lazy=True, max_rate=5.0,
    ),
    TopicBridgeSpec(
        "model/box/link/camera", "/model/box::link/camera", "sensor_msgs/msg/Image",
        "gz.msgs.Image", Direction.GZ_TO_ROS, lazy=True,
    ),
]  # fmt: skip


def test_the_yaml_reads_back_as_the_same_bridges_with_hints() -> None:
    out = io.StringIO()
    write_yaml(SPECS, header_lines(3.0, "ZeroMQ discovery on ...", 3), out)
    text = out.getvalue()
    result = parse_yaml(text, "discovered.yaml")
    assert (result.errors, result.warnings, result.patterns) == ((), (), ())
    read = [s for s in result.specs if isinstance(s, TopicBridgeSpec)]
    assert [
        (s.ros_topic, s.gz_topic, s.ros_type, s.direction, s.lazy, s.max_rate) for s in read
    ] == [(s.ros_topic, s.gz_topic, s.ros_type, s.direction, s.lazy, s.max_rate) for s in SPECS]
    assert [s.gz_type for s in read] == ["gz.msgs.Clock", "gz.msgs.Twist", "gz.msgs.Image"]
    assert "# /clock: rclcpp's time source subscribes best effort" in text
    assert "# a sensor stream: max_rate: <Hz>" in text
    assert text.startswith("# Written by parameter_bridge --discover 3: 3 Gazebo topics")


def test_entries_inferred_from_the_ros_publisher_say_so() -> None:
    inferred = TopicBridgeSpec(
        "model/robot1/cmd_vel", "/model/robot1/cmd_vel", "geometry_msgs/msg/Twist",
        "ignition.msgs.Twist", Direction.ROS_TO_GZ, lazy=True, source=AUTO_SOURCE,
        discovered_by=BY_ROS_PUBLISHER,
    )  # fmt: skip
    specs = [SPECS[0], inferred]
    out = io.StringIO()
    write_yaml(specs, header_lines(3.0, "ZeroMQ discovery on ...", 2, specs), out)
    text = out.getvalue()
    assert "# 1 entries (marked 'inferred') take their types from the ROS publisher" in text
    comment = "# inferred: /model/robot1/cmd_vel's Gazebo subscribers tell no type"
    assert text.count("# inferred:") == 1
    after = text.split(comment, 1)[1]
    assert after.split("\n")[1] == '- ros_topic_name: "model/robot1/cmd_vel"'
    read = parse_yaml(text, "discovered.yaml").specs[1]
    assert isinstance(read, TopicBridgeSpec)
    assert (read.ros_type, read.gz_type, read.direction) == (
        "geometry_msgs/msg/Twist", "gz.msgs.Twist", Direction.ROS_TO_GZ
    )  # fmt: skip


def test_nothing_discovered_is_an_empty_list() -> None:
    out = io.StringIO()
    write_yaml([], ["nothing"], out)
    assert parse_yaml(out.getvalue()).errors == ()


def test_the_discover_option_takes_optional_seconds() -> None:
    args = ["--discover", "/a@std_msgs/msg/String@gz.msgs.StringMsg"]
    assert split_seconds_option(args, DISCOVER_OPTION, 5.0) == (5.0, args[1:])
    assert split_seconds_option(["--discover", "2.5"], DISCOVER_OPTION, 5.0) == (2.5, [])
    assert split_seconds_option(["robot=r1", "--discover"], DISCOVER_OPTION, 5.0) == (
        5.0,
        ["robot=r1"],
    )
    with pytest.raises(UsageError, match="--discover takes a number of seconds > 0"):
        split_seconds_option(["--discover", "soon"], DISCOVER_OPTION, 5.0)


@pytest.mark.parametrize("text", ["inf", "Infinity", "nan", "-inf", "0"])
def test_the_seconds_are_a_finite_number_above_0(text: str) -> None:
    with pytest.raises(UsageError, match=f"a number of seconds > 0 .*, not '{text}'"):
        split_seconds_option(["--discover", text], DISCOVER_OPTION, 5.0)


def test_listening_ends_at_sigint_when_a_stop_signal_is_installed() -> None:
    interrupt = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT))
    with StopSignal() as stop:
        started = time.monotonic()
        interrupt.start()
        listened = listen(30.0, stop=stop)
        took = time.monotonic() - started
        interrupt.join()
    assert listened is False
    assert took < 15.0  # not the 30 s asked for


def test_listening_runs_its_time_without_a_stop_request() -> None:
    started = time.monotonic()
    assert listen(0.3) is True
    assert time.monotonic() - started >= 0.3
