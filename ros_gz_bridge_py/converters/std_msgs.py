"""std_msgs pairs (conversions.md §3.2) and the Header rules every stamped type shares (§1.3).

The header helpers here are the only place that knows how a ROS header maps onto the gz
``Header.data`` key/value list; other modules call them instead of touching ``data``.
"""

from __future__ import annotations

from typing import Any

from std_msgs.msg import Bool, ColorRGBA, Empty, Float32, Float64, Header, Int32, String, UInt32

from ros_gz_bridge_py.converters.builtin_interfaces import fill_gz_time, fill_ros_time
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

GzHeader = message_class("gz.msgs.Header")

FRAME_ID_KEY = "frame_id"
CHILD_FRAME_ID_KEY = "child_frame_id"


def gz_to_ros_frame(name: str) -> str:
    """Gazebo scoped name to ROS frame name: every ``::`` becomes ``/`` (left to right)."""
    return name.replace("::", "/")


def add_gz_header_entry(gz_header: Any, key: str, value: str) -> None:
    """Append ``{key: [value]}`` to a gz Header's ``data`` list."""
    entry = gz_header.data.add()
    entry.key = key
    entry.value.append(value)


def first_gz_header_value(gz_header: Any, key: str) -> str | None:
    """``value[0]`` of the first entry named ``key`` that has a value, else None."""
    for entry in gz_header.data:
        if entry.key == key and entry.value:
            return str(entry.value[0])
    return None


def last_gz_header_value(gz_header: Any, key: str) -> str | None:
    """``value[0]`` of the last entry named ``key`` that has a value, else None.

    The C++ header conversion loops without ``break``, so for ``frame_id`` the last one wins.
    """
    found: str | None = None
    for entry in gz_header.data:
        if entry.key == key and entry.value:
            found = str(entry.value[0])
    return found


def fill_gz_header(ros: Any, gz: Any) -> None:
    """ROS Header -> gz Header: the stamp (always present) and one ``frame_id`` entry."""
    gz.stamp.SetInParent()
    fill_gz_time(ros.stamp, gz.stamp)
    add_gz_header_entry(gz, FRAME_ID_KEY, ros.frame_id)


def fill_ros_header(gz: Any, ros: Any) -> None:
    """gz Header -> ROS Header: stamp, and the last ``frame_id`` entry with ``::`` as ``/``."""
    fill_ros_time(gz.stamp, ros.stamp)
    frame_id = last_gz_header_value(gz, FRAME_ID_KEY)
    if frame_id is not None:
        ros.frame_id = gz_to_ros_frame(frame_id)


def fill_gz_child_frame_id(child_frame_id: str, gz_header: Any) -> None:
    """Append the ``child_frame_id`` entry (after ``frame_id``, as TransformStamped/Odometry do)."""
    add_gz_header_entry(gz_header, CHILD_FRAME_ID_KEY, child_frame_id)


def ros_child_frame_id(gz_header: Any) -> str:
    """The first ``child_frame_id`` entry with ``::`` as ``/``, or ``""``."""
    value = first_gz_header_value(gz_header, CHILD_FRAME_ID_KEY)
    return "" if value is None else gz_to_ros_frame(value)


def header_to_gz(ros: Any) -> Any:
    gz = GzHeader()
    fill_gz_header(ros, gz)
    return gz


def header_to_ros(gz: Any) -> Any:
    ros = Header()
    fill_ros_header(gz, ros)
    return ros


def _data_pair(ros_class: type[Any], gz_name: str) -> Pair:
    """A pair for a ROS message and a gz message that both carry one ``data`` field."""
    gz_class = message_class(gz_name)

    def to_gz(ros: Any) -> Any:
        return gz_class(data=ros.data)

    def to_ros(gz: Any) -> Any:
        return ros_class(data=gz.data)

    return Pair(_ros_name(ros_class), gz_name, to_gz, to_ros, ros_class)


def _ros_name(ros_class: type[Any]) -> str:
    """``std_msgs/msg/Bool`` for the class ``std_msgs.msg.Bool``."""
    package = ros_class.__module__.split(".", 1)[0]
    return f"{package}/msg/{ros_class.__name__}"


def _rgba_pair() -> Pair:
    gz_class = message_class("gz.msgs.Color")

    def to_gz(ros: Any) -> Any:
        return gz_class(r=ros.r, g=ros.g, b=ros.b, a=ros.a)

    def to_ros(gz: Any) -> Any:
        return ColorRGBA(r=gz.r, g=gz.g, b=gz.b, a=gz.a)

    return Pair("std_msgs/msg/ColorRGBA", "gz.msgs.Color", to_gz, to_ros, ColorRGBA)


def _empty_pair() -> Pair:
    """Nothing is copied either way; gz ``unused`` stays false."""
    gz_class = message_class("gz.msgs.Empty")

    def to_gz(_ros: Any) -> Any:
        return gz_class()

    def to_ros(_gz: Any) -> Any:
        return Empty()

    return Pair("std_msgs/msg/Empty", "gz.msgs.Empty", to_gz, to_ros, Empty)


PAIRS = (
    _data_pair(Bool, "gz.msgs.Boolean"),
    _rgba_pair(),
    _empty_pair(),
    _data_pair(Float32, "gz.msgs.Float"),
    _data_pair(Float64, "gz.msgs.Double"),
    Pair("std_msgs/msg/Header", "gz.msgs.Header", header_to_gz, header_to_ros, Header),
    _data_pair(Int32, "gz.msgs.Int32"),
    _data_pair(String, "gz.msgs.StringMsg"),
    _data_pair(UInt32, "gz.msgs.UInt32"),
)
