"""std_msgs pairs and the shared Header rules (docs/conversions.md §1.3,
docs/conversions-per-package.md §3.2)."""

from __future__ import annotations

from typing import Any

import pytest
from std_msgs.msg import Bool, ColorRGBA, Empty, Float32, Float64, Header, Int32, String, UInt32

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import PAIRS, gz_to_ros_frame
from ros_gz_bridge_py.msgs import message_class

GzHeader = message_class("gz.msgs.Header")
BY_ROS = {pair.ros_type: pair for pair in PAIRS}


def pair(name: str) -> Pair:
    return BY_ROS[f"std_msgs/msg/{name}"]


@pytest.mark.parametrize(
    ("ros_msg", "gz_type"),
    [
        (Bool(data=True), "gz.msgs.Boolean"),
        (Float32(data=-2.25), "gz.msgs.Float"),
        (Float64(data=1e-300), "gz.msgs.Double"),
        (Int32(data=-(2**31)), "gz.msgs.Int32"),
        (UInt32(data=2**32 - 1), "gz.msgs.UInt32"),
        (String(data="häst::x"), "gz.msgs.StringMsg"),
    ],
)
def test_data_pairs_round_trip(ros_msg: Any, gz_type: str) -> None:
    conv = pair(type(ros_msg).__name__)
    assert conv.gz_type == gz_type
    gz = conv.to_gz(ros_msg)
    assert gz.DESCRIPTOR.full_name == gz_type
    assert gz.data == ros_msg.data
    assert not gz.HasField("header")
    assert conv.to_ros(gz) == ros_msg


def test_color_round_trips() -> None:
    ros = ColorRGBA(r=0.25, g=0.5, b=0.75, a=1.0)
    gz = pair("ColorRGBA").to_gz(ros)
    assert (gz.r, gz.g, gz.b, gz.a) == (0.25, 0.5, 0.75, 1.0)
    assert pair("ColorRGBA").to_ros(gz) == ros


def test_empty_copies_nothing() -> None:
    gz = pair("Empty").to_gz(Empty())
    assert gz.SerializeToString() == b""
    assert pair("Empty").to_ros(gz) == Empty()


def test_header_to_gz_writes_stamp_and_one_frame_id_entry() -> None:
    ros = Header(frame_id="")
    ros.stamp.sec, ros.stamp.nanosec = 2, 3
    gz = pair("Header").to_gz(ros)
    assert gz.HasField("stamp")
    assert (gz.stamp.sec, gz.stamp.nsec) == (2, 3)
    assert [(d.key, list(d.value)) for d in gz.data] == [("frame_id", [""])]


def test_header_to_ros_takes_last_frame_id_and_ignores_other_keys() -> None:
    gz = GzHeader()
    gz.stamp.sec, gz.stamp.nsec = 2, 3
    gz.data.add(key="seq", value=["1"])
    gz.data.add(key="frame_id", value=["first"])
    gz.data.add(key="frame_id")  # no value: skipped
    gz.data.add(key="frame_id", value=["model::link::sensor", "ignored"])
    ros = pair("Header").to_ros(gz)
    assert ros.frame_id == "model/link/sensor"
    assert (ros.stamp.sec, ros.stamp.nanosec) == (2, 3)


def test_header_without_frame_id_gives_empty() -> None:
    assert pair("Header").to_ros(GzHeader()).frame_id == ""


@pytest.mark.parametrize(
    ("name", "expected"), [("a::b::c", "a/b/c"), ("a:::b", "a/:b"), ("plain", "plain")]
)
def test_gz_to_ros_frame(name: str, expected: str) -> None:
    assert gz_to_ros_frame(name) == expected
