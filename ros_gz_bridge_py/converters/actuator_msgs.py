"""actuator_msgs/msg/Actuators <-> gz.msgs.Actuators (conversions.md §3.10).

The three float64 lists are copied whole, in order, with their lengths.
"""

from __future__ import annotations

from array import array
from typing import Any

import numpy as np
from actuator_msgs.msg import Actuators

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import fill_gz_header, fill_ros_header
from ros_gz_bridge_py.msgs import message_class

_GzActuators = message_class("gz.msgs.Actuators")


def _doubles(repeated: Any) -> array[float]:
    """A ROS float64[] value; numpy reads the repeated field as one buffer, no per-item loop."""
    return array("d", np.asarray(repeated, dtype=np.float64).tobytes())


def actuators_to_gz(ros: Any) -> Any:
    gz = _GzActuators()
    fill_gz_header(ros.header, gz.header)
    gz.position.extend(ros.position)
    gz.velocity.extend(ros.velocity)
    gz.normalized.extend(ros.normalized)
    return gz


def actuators_to_ros(gz: Any) -> Any:
    ros = Actuators()
    fill_ros_header(gz.header, ros.header)
    ros.position = _doubles(gz.position)
    ros.velocity = _doubles(gz.velocity)
    ros.normalized = _doubles(gz.normalized)
    return ros


PAIRS = (
    Pair(
        "actuator_msgs/msg/Actuators",
        "gz.msgs.Actuators",
        actuators_to_gz,
        actuators_to_ros,
        Actuators,
    ),
)
