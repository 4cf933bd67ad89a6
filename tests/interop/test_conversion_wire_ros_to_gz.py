"""Wire-level conversions, ROS to Gazebo: for a few pairs, our ``to_gz`` output is serialized,
published by our ZmqGzNode under ``ignition.msgs.X`` and printed by the C++ peer's ``echo`` mode
(decoded with the Fortress schema compiled into ign-msgs 8); the printed text is checked for the
expected fields and parsed back into the message we sent (the other direction:
``test_conversion_wire.py``). The sections cited are those of docs/conversions.md and
docs/conversions-per-package.md.

All deliveries happen once per module, in a module-scoped fixture that runs a few echoes at a
time and stops every process it started before the first test runs.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pytest
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from google.protobuf import text_format
from rcl_interfaces.msg import ParameterType, ParameterValue
from ros_gz_interfaces.msg import (
    LogicalCameraImage,
    LogicalCameraImageModel,
    LogPlaybackStatistics,
)
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import (
    Imu,
    JointState,
    LaserScan,
)
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import (
    PeerProcess,
    peer_binary,
    start_peer,
    stop_processes,
    unique_name,
)
from tests.interop.wire_runs import DELIVERY_TIMEOUT, PARALLEL, run_limited

pytestmark = pytest.mark.peer


def stamp(msg: Any, frame: str, sec: int = 21, nanosec: int = 22) -> Any:
    msg.header.frame_id = frame
    msg.header.stamp = Time(sec=sec, nanosec=nanosec)
    return msg


def ros_imu() -> Any:
    imu = stamp(Imu(), "imu_link")
    imu.orientation.x, imu.orientation.y, imu.orientation.z, imu.orientation.w = 0, 0, 0.6, 0.8
    imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = 1.5, -2.25, 3.125
    imu.linear_acceleration.x = 9.5
    imu.linear_acceleration.y = 0.25
    imu.linear_acceleration.z = -9.75
    imu.orientation_covariance = [float(i) for i in range(1, 10)]
    return imu


def ros_tf() -> Any:
    first = stamp(TransformStamped(), "world", 1, 2)
    first.child_frame_id = "robot/base"
    first.transform.translation.x = 1.5
    first.transform.rotation.w = 1.0
    second = stamp(TransformStamped(), "robot/base", 3, 4)
    second.child_frame_id = "robot/arm"
    second.transform.translation.z = -0.5
    second.transform.rotation.x = 1.0
    return TFMessage(transforms=[first, second])


def ros_scan() -> Any:
    scan = stamp(LaserScan(), "laser")
    scan.angle_min, scan.angle_max, scan.angle_increment = -1.0, 1.0, 0.5
    scan.range_min, scan.range_max = 0.25, 12.0
    scan.ranges = [1.0, 2.0, 3.0, 4.0, 5.0]
    scan.intensities = [10.0, 20.0, 30.0, 40.0, 50.0]
    return scan


def ros_joint_state() -> Any:
    state = stamp(JointState(), "arm")
    state.name = ["wrist", "finger"]
    state.position = [0.5, 1.5]
    state.velocity = [-0.25, 0.0]
    state.effort = [3.5, -4.5]
    return state


def ros_logical_camera() -> Any:
    image = stamp(LogicalCameraImage(), "camera")
    image.pose.position.x = 1.5
    box = LogicalCameraImageModel(name="box")
    box.pose.position.y = -2.5
    box.pose.orientation.z, box.pose.orientation.w = 1.0, 0.0
    shelf = LogicalCameraImageModel(name="shelf::top")
    shelf.pose.position.z = 3.25
    image.model = [box, shelf]
    return image


def ros_log_playback() -> Any:
    log = stamp(LogPlaybackStatistics(), "log", 31, 32)
    log.start_time = Time(sec=100, nanosec=200)
    return log


@dataclass(frozen=True)
class Reverse:
    """One ROS -> Gazebo conversion checked on the C++ side."""

    name: str
    ros_type: str
    gz_type: str
    make: Callable[[], Any]
    #: Substrings the C++ echo's one-line text format must contain.
    expected: tuple[str, ...]
    #: Top-level fields the text must not mention.
    absent: tuple[str, ...] = ()


REVERSES = (
    Reverse("imu", "sensor_msgs/msg/Imu", "ignition.msgs.IMU", ros_imu, (
        'header { stamp { sec: 21 nsec: 22 } data { key: "frame_id" value: "imu_link" } }',
        'entity_name: "imu_link"',
        # proto3 text omits zero scalars.
        "orientation { z: 0.6 w: 0.8 }",
        "angular_velocity { x: 1.5 y: -2.25 z: 3.125 }",
        "linear_acceleration { x: 9.5 y: 0.25 z: -9.75 }",
    )),
    Reverse("tf", "tf2_msgs/msg/TFMessage", "ignition.msgs.Pose_V", ros_tf, (
        'header { stamp { sec: 1 nsec: 2 } data { key: "frame_id" value: "world" } }'
        ' pose { header { stamp { sec: 1 nsec: 2 } data { key: "frame_id" value: "world" } '
        'data { key: "child_frame_id" value: "robot/base" } }'
        " position { x: 1.5 } orientation { w: 1 } }",
        'pose { header { stamp { sec: 3 nsec: 4 } data { key: "frame_id" value: "robot/base" }'
        ' data { key: "child_frame_id" value: "robot/arm" } }'
        " position { z: -0.5 } orientation { x: 1 w: 1 } }",
    )),
    Reverse("laser_scan", "sensor_msgs/msg/LaserScan", "ignition.msgs.LaserScan", ros_scan, (
        'frame: "laser"',
        "angle_min: -1 angle_max: 1 angle_step: 0.5 range_min: 0.25 range_max: 12",
        # count = trunc((max - min) / increment) = 4: the last sample is dropped
        # (docs/conversions-per-package.md §3.5).
        "count: 4",
        "ranges: 1 ranges: 2 ranges: 3 ranges: 4 intensities: 10",
        "intensities: 40",
    ), ("ranges: 5", "intensities: 50", "vertical_count", "world_pose")),
    Reverse("clock", "rosgraph_msgs/msg/Clock", "ignition.msgs.Clock",
            lambda: Clock(clock=Time(sec=12, nanosec=345)), (
        "sim { sec: 12 nsec: 345 }",
    ), ("header", "system", "real")),
    Reverse("any", "rcl_interfaces/msg/ParameterValue", "ignition.msgs.Any",
            lambda: ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=False), (
        # The oneof member is set even for false (§1.6), so the text names it.
        "type: BOOLEAN bool_value: false",
    ), ("header",)),
    Reverse("logical_camera", "ros_gz_interfaces/msg/LogicalCameraImage",
            "ignition.msgs.LogicalCameraImage", ros_logical_camera, (
        'header { stamp { sec: 21 nsec: 22 } data { key: "frame_id" value: "camera" } }',
        "pose { position { x: 1.5 } orientation { w: 1 } }",
        'model { name: "box" pose { position { y: -2.5 } orientation { z: 1 } } }',
        'model { name: "shelf::top" pose { position { z: 3.25 } orientation { w: 1 } } }',
    )),
    Reverse("log_playback", "ros_gz_interfaces/msg/LogPlaybackStatistics",
            "ignition.msgs.LogPlaybackStatistics", ros_log_playback, (
        'header { stamp { sec: 31 nsec: 32 } data { key: "frame_id" value: "log" } }',
        "start_time { sec: 100 nsec: 200 }",
        # A zero end time is still sent.
        "end_time { }",
    )),
    Reverse("joint_state", "sensor_msgs/msg/JointState", "ignition.msgs.Model",
            ros_joint_state, (
        'joint { name: "wrist" axis1 { position: 0.5 velocity: -0.25 force: 3.5 } }',
        'joint { name: "finger" axis1 { position: 1.5 force: -4.5 } }',
    )),
)  # fmt: skip


class _Echoing:
    """One reverse case in flight: the C++ echo and our publisher of the converted bytes."""

    def __init__(self, node: Any, reverse: Reverse) -> None:
        self.reverse = reverse
        self.node = node
        self.topic = unique_name(f"wire_rev_{reverse.name}")
        pair = default_registry().get(reverse.ros_type, reverse.gz_type)
        self.sent = pair.to_gz(reverse.make())
        self.payload = self.sent.SerializeToString()
        self.publisher: Any = None
        self.proc: PeerProcess | None = None
        self.started = 0.0
        self.output = ""

    def start(self) -> None:
        self.started = time.monotonic()
        self.proc = start_peer("echo", self.topic, self.reverse.gz_type, "20", "--count", "1")
        self.publisher = self.node.advertise(self.topic, self.reverse.gz_type)

    def step(self) -> bool:
        assert self.proc is not None
        finished = self.proc.poll() is not None
        if not finished and time.monotonic() - self.started < DELIVERY_TIMEOUT:
            if self.publisher.has_connections():
                self.publisher.publish_raw(self.payload)
            return False
        self.proc.stop()
        self.output = self.proc.output()
        self.publisher.close()
        return True


@pytest.fixture(scope="module")
def echoes(module_gz_node: Any) -> dict[str, _Echoing]:
    """Every reverse case delivered to the C++ echo once; all processes stopped before return."""
    peer_binary()
    jobs = [_Echoing(module_gz_node, reverse) for reverse in REVERSES]
    try:
        run_limited(jobs, PARALLEL)
    finally:
        stop_processes()
    return {job.reverse.name: job for job in jobs}


@pytest.mark.parametrize("reverse", REVERSES, ids=[r.name for r in REVERSES])
def test_our_to_gz_bytes_are_read_by_the_cpp_echo(
    reverse: Reverse, echoes: dict[str, _Echoing]
) -> None:
    echo = echoes[reverse.name]
    lines = re.findall(rf"^MSG {re.escape(reverse.gz_type)} (.*)$", echo.output, re.M)
    assert len(lines) == 1, echo.output
    text = lines[0]
    assert "UNDECODABLE" not in text

    for expected in reverse.expected:
        assert expected in text, text
    top_level = text
    while (inner := re.sub(r"\{[^{}]*\}", "", top_level)) != top_level:
        top_level = inner
    for name in reverse.absent:
        assert not re.search(rf"\b{name}\b", top_level), text
    parsed = text_format.Parse(text, message_class(reverse.gz_type)())
    assert parsed == echo.sent
