"""tf2_msgs/msg/TFMessage <-> gz.msgs.Pose_V (docs/conversions-per-package.md §3.7)."""

from __future__ import annotations

from typing import Any

import pytest

tf2_msg = pytest.importorskip(
    "tf2_msgs.msg", reason="tf2_msgs is built by tools/setup_interfaces.sh"
)

from geometry_msgs.msg import TransformStamped  # noqa: E402

from ros_gz_bridge_py.converters.tf2_msgs import tf_message_to_gz, tf_message_to_ros  # noqa: E402
from ros_gz_bridge_py.msgs import message_class  # noqa: E402


def transform(parent: str, child: str, x: float) -> Any:
    msg = TransformStamped(child_frame_id=child)
    msg.header.frame_id = parent
    msg.header.stamp.sec = int(x)
    msg.transform.translation.x = x
    msg.transform.rotation.w = 1.0
    return msg


def test_each_pose_carries_its_own_header_and_the_first_one_heads_the_vector() -> None:
    ros = tf2_msg.TFMessage(transforms=[transform("world", "a", 1.0), transform("a", "b", 2.0)])
    gz = tf_message_to_gz(ros)
    assert [(d.key, list(d.value)) for d in gz.header.data] == [("frame_id", ["world"])]
    assert gz.header.stamp.sec == 1
    assert [[(d.key, list(d.value)) for d in p.header.data] for p in gz.pose] == [
        [("frame_id", ["world"]), ("child_frame_id", ["a"])],
        [("frame_id", ["a"]), ("child_frame_id", ["b"])],
    ]
    assert tf_message_to_ros(gz) == ros


def test_empty_message_has_no_header() -> None:
    gz = tf_message_to_gz(tf2_msg.TFMessage())
    assert not gz.HasField("header")
    assert len(gz.pose) == 0


def test_to_ros_ignores_the_vector_header_and_pose_names() -> None:
    gz = message_class("gz.msgs.Pose_V")()
    gz.header.data.add(key="frame_id", value=["top"])
    pose = gz.pose.add(name="robot")
    pose.header.data.add(key="frame_id", value=["world"])
    pose.header.data.add(key="child_frame_id", value=["robot::chassis"])
    (only,) = tf_message_to_ros(gz).transforms
    assert (only.header.frame_id, only.child_frame_id) == ("world", "robot/chassis")
