"""actuator_msgs/msg/Actuators <-> gz.msgs.Actuators (docs/conversions-per-package.md §3.10)."""

from __future__ import annotations

from actuator_msgs.msg import Actuators

from ros_gz_bridge_py.converters.actuator_msgs import actuators_to_gz, actuators_to_ros
from ros_gz_bridge_py.msgs import message_class

GzActuators = message_class("gz.msgs.Actuators")


def test_actuators_convert_and_round_trip() -> None:
    ros = Actuators(position=[1.5, -2.25, 3.125], velocity=[10.5], normalized=[0.25, -0.75])
    ros.header.stamp.sec = 2
    ros.header.stamp.nanosec = 3
    ros.header.frame_id = "base_link"
    gz = actuators_to_gz(ros)
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (2, 3)
    assert [(d.key, list(d.value)) for d in gz.header.data] == [("frame_id", ["base_link"])]
    assert list(gz.position) == [1.5, -2.25, 3.125]
    assert list(gz.velocity) == [10.5]
    assert list(gz.normalized) == [0.25, -0.75]
    assert actuators_to_ros(gz) == ros


def test_empty_actuators_keep_empty_lists_and_a_header() -> None:
    gz = actuators_to_gz(Actuators())
    assert gz.HasField("header")
    assert (len(gz.position), len(gz.velocity), len(gz.normalized)) == (0, 0, 0)
    back = actuators_to_ros(GzActuators())
    assert (len(back.position), len(back.velocity), len(back.normalized)) == (0, 0, 0)


def test_large_lists_are_copied_whole() -> None:
    values = [i * 0.5 for i in range(10_000)]
    ros = Actuators(position=values, velocity=values[::-1], normalized=values[:3])
    back = actuators_to_ros(actuators_to_gz(ros))
    assert list(back.position) == values
    assert list(back.velocity) == values[::-1]
    assert list(back.normalized) == values[:3]
