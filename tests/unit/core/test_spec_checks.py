"""A spec built in Python is checked as the YAML parser checks an entry (core/spec_checks.py)."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import Direction, ServiceBridgeSpec, TopicBridgeSpec
from ros_gz_bridge_py.core.spec_checks import checked_spec
from ros_gz_bridge_py.errors import ConfigError


def spec(direction: object, source: str = "") -> TopicBridgeSpec:
    return TopicBridgeSpec(
        "/odom", "/odom", "nav_msgs/msg/Odometry", "gz.msgs.Odometry",
        direction,  # type: ignore[arg-type]
        source=source,
    )  # fmt: skip


def test_a_deprecated_direction_is_taken_with_one_warning_naming_the_entry() -> None:
    warned: list[str] = []
    checked = checked_spec(spec("IGN_TO_ROS", "bridge.yaml entry 2 (line 5)"), warned.append)
    assert isinstance(checked, TopicBridgeSpec)
    assert checked.direction is Direction.GZ_TO_ROS
    assert warned == [
        "bridge.yaml entry 2 (line 5): direction IGN_TO_ROS is deprecated, use GZ_TO_ROS"
    ]
    warned.clear()
    assert checked_spec(spec("ROS_TO_IGN"), warned.append).direction is Direction.ROS_TO_GZ  # type: ignore[union-attr]
    assert warned == ["/odom: direction ROS_TO_IGN is deprecated, use ROS_TO_GZ"]


def test_the_current_spellings_say_nothing_and_an_unknown_one_is_refused() -> None:
    warned: list[str] = []
    for direction in (Direction.BIDIRECTIONAL, "GZ_TO_ROS"):
        checked_spec(spec(direction), warned.append)
    assert warned == []
    with pytest.raises(ConfigError, match="direction 'SIDEWAYS' is none of"):
        checked_spec(spec("SIDEWAYS"), warned.append)


def test_a_service_with_one_gazebo_type_of_two_is_refused_as_in_yaml() -> None:
    """Bridge.add took it and logged '-> gz.msgs.WorldControl/)'; YAML and the CLI refuse it."""
    warned: list[str] = []
    half = ServiceBridgeSpec(
        "/world/control", "ros_gz_interfaces/srv/ControlWorld", gz_req_type="gz.msgs.WorldControl"
    )
    with pytest.raises(ConfigError, match=r"set both gz_req_type and gz_rep_type, or neither"):
        checked_spec(half, warned.append)
    both = ServiceBridgeSpec(
        "/world/control", "ros_gz_interfaces/srv/ControlWorld", "gz.msgs.WorldControl",
        "gz.msgs.Boolean",
    )  # fmt: skip
    assert checked_spec(both, warned.append) == both
    neither = ServiceBridgeSpec("/world/control", "ros_gz_interfaces/srv/ControlWorld")
    assert checked_spec(neither, warned.append) == neither
