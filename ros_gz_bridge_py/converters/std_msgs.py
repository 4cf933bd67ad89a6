"""std_msgs pairs (docs/conversions-per-package.md §3.2) and the Header rules every stamped type
shares (docs/conversions.md §1.3).

The header helpers here are the only place that knows how a ROS header maps onto the gz
``Header.data`` key/value list; other modules call them instead of touching ``data``.
"""

from __future__ import annotations

from typing import Any

from std_msgs.msg import Bool, ColorRGBA, Empty, Float32, Float64, Header, Int32, String, UInt32

from ros_gz_bridge_py.converters._fields import Fill, fields, fill_pair
from ros_gz_bridge_py.converters.builtin_interfaces import fill_gz_present_time, fill_ros_time

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
    fill_gz_present_time(ros.stamp, gz.stamp)
    add_gz_header_entry(gz, FRAME_ID_KEY, ros.frame_id)


def fill_ros_header(gz: Any, ros: Any) -> None:
    """gz Header -> ROS Header: stamp, and the last ``frame_id`` entry with ``::`` as ``/``."""
    fill_ros_time(gz.stamp, ros.stamp)
    frame_id = last_gz_header_value(gz, FRAME_ID_KEY)
    if frame_id is not None:
        ros.frame_id = gz_to_ros_frame(frame_id)


def _fill_gz_frames(ros: Any, gz: Any) -> None:
    """ROS ``header`` and ``child_frame_id`` -> gz ``header``: a ``child_frame_id`` entry after
    ``frame_id``."""
    fill_gz_header(ros.header, gz.header)
    add_gz_header_entry(gz.header, CHILD_FRAME_ID_KEY, ros.child_frame_id)


def _fill_ros_frames(gz: Any, ros: Any) -> None:
    """The first ``child_frame_id`` entry with ``::`` as ``/``, or ``""``."""
    fill_ros_header(gz.header, ros.header)
    child_frame_id = first_gz_header_value(gz.header, CHILD_FRAME_ID_KEY)
    ros.child_frame_id = "" if child_frame_id is None else gz_to_ros_frame(child_frame_id)


HEADER = Fill(fill_gz_header, fill_ros_header)
#: A message with a header and a ``child_frame_id`` (TransformStamped, Odometry) <-> the gz
#: header, where ``child_frame_id`` is an entry of its own.
FRAMES = Fill(_fill_gz_frames, _fill_ros_frames)
COLOR = fields("r", "g", "b", "a")
#: The single-field messages: ``data`` on both sides.
_DATA = fields("data")
#: Nothing is copied either way; gz ``unused`` stays false.
_NOTHING = fields()

PAIRS = (
    fill_pair(Bool, "gz.msgs.Boolean", _DATA),
    fill_pair(ColorRGBA, "gz.msgs.Color", COLOR),
    fill_pair(Empty, "gz.msgs.Empty", _NOTHING),
    fill_pair(Float32, "gz.msgs.Float", _DATA),
    fill_pair(Float64, "gz.msgs.Double", _DATA),
    fill_pair(Header, "gz.msgs.Header", HEADER),
    fill_pair(Int32, "gz.msgs.Int32", _DATA),
    fill_pair(String, "gz.msgs.StringMsg", _DATA),
    fill_pair(UInt32, "gz.msgs.UInt32", _DATA),
)
