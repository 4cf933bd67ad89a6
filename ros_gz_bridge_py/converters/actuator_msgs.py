"""actuator_msgs/msg/Actuators <-> gz.msgs.Actuators (docs/conversions-per-package.md §3.10).

The three float64 lists are copied whole, in order, with their lengths.
"""

from __future__ import annotations

from actuator_msgs.msg import Actuators

from ros_gz_bridge_py.converters._fields import converters, fields, numbers
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER

actuators_to_gz, actuators_to_ros = converters(
    fields(
        ("header", HEADER),
        ("position", numbers("d")),
        ("velocity", numbers("d")),
        ("normalized", numbers("d")),
    ),
    Actuators,
    "gz.msgs.Actuators",
)

PAIRS = (Pair.of(Actuators, "gz.msgs.Actuators", actuators_to_gz, actuators_to_ros),)
