"""Example converter plugin: ``std_msgs/msg/UInt8MultiArray`` <-> ``gz.msgs.Bytes``.

Both types exist on their side and the bridge does not pair them itself. The bytes are
copied as they are; the ROS ``layout`` has no Gazebo counterpart, so it is dropped (R→G)
and left empty (G→R).
"""

from __future__ import annotations

from typing import Any

from std_msgs.msg import UInt8MultiArray

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.msgs import message_class

GzBytes = message_class("gz.msgs.Bytes")


def uint8_multi_array_to_gz(ros: Any) -> Any:
    return GzBytes(data=bytes(ros.data))


def uint8_multi_array_to_ros(gz: Any) -> Any:
    return UInt8MultiArray(data=gz.data)


PAIRS = (
    Pair(
        "std_msgs/msg/UInt8MultiArray",
        "gz.msgs.Bytes",
        uint8_multi_array_to_gz,
        uint8_multi_array_to_ros,
        UInt8MultiArray,
    ),
)
