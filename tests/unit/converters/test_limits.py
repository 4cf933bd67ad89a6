"""Lists of submessages that would grow too much in ROS are refused before their items are
made (converters/_limits.py; docs/conversions.md §1.1)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from geometry_msgs.msg import Pose, PoseArray

from ros_gz_bridge_py.converters._fields import each
from ros_gz_bridge_py.converters._limits import OUTPUT_FLOOR, OUTPUT_RATIO, least_item_bytes
from ros_gz_bridge_py.converters.geometry_msgs import POSE
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

POSE_V = message_class("gz.msgs.Pose_V")


def _pose_array_to_ros() -> Callable[[Any], Any]:
    pair = default_registry().find("geometry_msgs/msg/PoseArray", "gz.msgs.Pose_V")
    assert pair is not None
    return pair.to_ros


def _empty_poses(count: int) -> Any:
    msg = POSE_V()
    for _ in range(count):
        msg.pose.add()
    return msg


def test_a_default_item_is_the_least_an_item_writes() -> None:
    assert least_item_bytes(Pose) == 7 * 8  # position and orientation, 7 doubles


def test_empty_elements_up_to_the_floor_are_converted() -> None:
    count = OUTPUT_FLOOR // least_item_bytes(Pose)
    ros = _pose_array_to_ros()(_empty_poses(count))
    assert len(ros.poses) == count


def test_empty_elements_past_the_bound_are_refused_naming_count_and_limit() -> None:
    msg = _empty_poses(5000)
    limit = OUTPUT_FLOOR + OUTPUT_RATIO * msg.ByteSize()
    with pytest.raises(ConversionError, match=rf"5000 Pose items .* limit of {limit}\b"):
        _pose_array_to_ros()(msg)


def test_elements_with_their_fields_set_pass_in_any_number() -> None:
    msg = POSE_V()
    for k in range(5000):
        pose = msg.pose.add()
        pose.position.x, pose.orientation.w = k + 0.5, 1.0
    ros = _pose_array_to_ros()(msg)
    assert len(ros.poses) == 5000
    assert ros.poses[-1].position.x == 4999.5


def test_a_list_filled_on_its_own_is_bounded_by_its_elements() -> None:
    """A list Fill used outside a whole-message converter measures its own elements."""
    fill = each(POSE, Pose)
    with pytest.raises(ConversionError, match="5000 Pose items"):
        fill.to_ros(_empty_poses(5000).pose, PoseArray().poses)
