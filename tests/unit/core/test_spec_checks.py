"""A spec built in Python is checked as the YAML parser checks an entry (core/spec_checks.py)."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
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
