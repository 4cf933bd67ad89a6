"""The benchmark messages: a ROS message of each kind, its Gazebo twin, and the send-time stamp.

Every kind names one registry pair. The stamp is CLOCK_MONOTONIC in nanoseconds, written into
the field the bridge carries across unchanged (a header stamp, the clock, or — for Twist, which
has no header — ``linear.x`` as seconds), so a receiver in another process computes latency.
Gazebo messages are built with the registry's own ``to_gz`` from the ROS message.
"""

from __future__ import annotations

import math
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ros_gz_bridge_py.converters.registry import Pair, default_registry

NS = 1_000_000_000


@dataclass(frozen=True)
class Kind:
    """One benchmark message kind."""

    name: str
    ros_type: str
    gz_type: str
    make_ros: Callable[[], Any]
    #: Where the stamp lives: "header", "transform", "clock" or "twist".
    stamp_at: str

    @property
    def pair(self) -> Pair:
        return default_registry().get(self.ros_type, self.gz_type)

    @property
    def has_header(self) -> bool:
        return self.stamp_at == "header"

    @property
    def gz_stamp_path(self) -> str:
        """Where the stamp lives in the Gazebo message, as the C++ peer's ``--stamp`` path."""
        return _GZ_STAMP_PATHS[self.stamp_at]

    @property
    def ignition_type(self) -> str:
        """The Fortress (ignition-msgs8) name of :attr:`gz_type`, for the C++ peer."""
        return self.gz_type.replace("gz.msgs.", "ignition.msgs.", 1)


_GZ_STAMP_PATHS = {
    "header": "header.stamp",
    "transform": "pose.0.header.stamp",
    "clock": "sim",
    "twist": "linear.x",
}


def _image(width: int, height: int) -> Any:
    from sensor_msgs.msg import Image  # noqa: PLC0415 - ROS imports only where used

    msg = Image(width=width, height=height, encoding="rgb8", step=width * 3)
    msg.header.frame_id = "camera"
    msg.data = bytes(range(256)) * (width * height * 3 // 256) + bytes(width * height * 3 % 256)
    return msg


def _cloud(size: int) -> Any:
    from sensor_msgs.msg import PointCloud2, PointField  # noqa: PLC0415

    point_step = 16
    fields = [
        PointField(name=name, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, name in enumerate(("x", "y", "z", "intensity"))
    ]
    width = size // point_step
    msg = PointCloud2(height=1, width=width, fields=fields, point_step=point_step)
    msg.row_step = width * point_step
    msg.is_dense = True
    msg.header.frame_id = "lidar"
    msg.data = bytes(width * point_step)
    return msg


def _scan(rays: int) -> Any:
    from sensor_msgs.msg import LaserScan  # noqa: PLC0415

    step = 2 * math.pi / rays
    msg = LaserScan(angle_min=-math.pi, angle_max=math.pi - step, angle_increment=step)
    msg.range_min, msg.range_max = 0.1, 30.0
    msg.ranges = [float(i % 300) / 10.0 for i in range(rays)]
    msg.intensities = [1.0] * rays
    msg.header.frame_id = "laser"
    return msg


def _tf(count: int) -> Any:
    from geometry_msgs.msg import TransformStamped  # noqa: PLC0415
    from tf2_msgs.msg import TFMessage  # noqa: PLC0415

    transforms = []
    for i in range(count):
        transform = TransformStamped()
        transform.header.frame_id = "odom" if i == 0 else f"link_{i - 1}"
        transform.child_frame_id = f"link_{i}"
        transform.transform.translation.x = 0.1 * i
        transform.transform.rotation.w = 1.0
        transforms.append(transform)
    return TFMessage(transforms=transforms)


def _twist() -> Any:
    from geometry_msgs.msg import Twist  # noqa: PLC0415

    msg = Twist()
    msg.angular.z = 0.5
    return msg


def _odometry() -> Any:
    from nav_msgs.msg import Odometry  # noqa: PLC0415

    msg = Odometry(child_frame_id="base_link")
    msg.header.frame_id = "odom"
    msg.pose.pose.orientation.w = 1.0
    msg.pose.covariance = [0.01] * 36
    msg.twist.covariance = [0.01] * 36
    return msg


def _imu() -> Any:
    from sensor_msgs.msg import Imu  # noqa: PLC0415

    msg = Imu()
    msg.header.frame_id = "imu_link"
    msg.orientation.w = 1.0
    msg.angular_velocity.z = 0.25
    msg.linear_acceleration.z = 9.81
    for covariance in ("orientation", "angular_velocity", "linear_acceleration"):
        setattr(msg, f"{covariance}_covariance", [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01])
    return msg


def _joint_states() -> Any:
    """Two wheels, as the fleet's simulator sends them (testing/fleet_sim.py)."""
    from sensor_msgs.msg import JointState  # noqa: PLC0415

    msg = JointState(name=["left_wheel", "right_wheel"], position=[1.5, -1.5])
    msg.velocity = [0.25, -0.25]
    msg.effort = [0.0, 0.0]
    return msg


def _clock() -> Any:
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415

    return Clock()


IMAGE, POINTS = "sensor_msgs/msg/Image", "sensor_msgs/msg/PointCloud2"
KINDS = {
    kind.name: kind
    for kind in (
        Kind("image640", IMAGE, "gz.msgs.Image", lambda: _image(640, 480), "header"),
        Kind("image1080", IMAGE, "gz.msgs.Image", lambda: _image(1920, 1080), "header"),
        Kind("cloud1mb", POINTS, "gz.msgs.PointCloudPacked", lambda: _cloud(1 << 20), "header"),
        Kind(
            "scan1440",
            "sensor_msgs/msg/LaserScan",
            "gz.msgs.LaserScan",
            lambda: _scan(1440),
            "header",
        ),
        Kind("tf50", "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V", lambda: _tf(50), "transform"),
        Kind("tf20", "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V", lambda: _tf(20), "transform"),
        Kind("twist", "geometry_msgs/msg/Twist", "gz.msgs.Twist", _twist, "twist"),
        Kind("odometry", "nav_msgs/msg/Odometry", "gz.msgs.Odometry", _odometry, "header"),
        Kind("imu", "sensor_msgs/msg/Imu", "gz.msgs.IMU", _imu, "header"),
        Kind("clock", "rosgraph_msgs/msg/Clock", "gz.msgs.Clock", _clock, "clock"),
        Kind(
            "joint_states", "sensor_msgs/msg/JointState", "gz.msgs.Model", _joint_states, "header"
        ),
    )
}


def now_ns() -> int:
    return time.monotonic_ns()


def _ros_time(kind: Kind, msg: Any) -> Any:
    """The builtin_interfaces/Time of a ROS message of ``kind`` that carries the stamp."""
    if kind.stamp_at == "clock":
        return msg.clock
    if kind.stamp_at == "transform":
        return msg.transforms[0].header.stamp
    return msg.header.stamp


def _gz_time(kind: Kind, msg: Any) -> Any:
    """The gz.msgs.Time of a Gazebo message of ``kind`` that carries the stamp."""
    if kind.stamp_at == "clock":
        return msg.sim
    if kind.stamp_at == "transform":
        return msg.pose[0].header.stamp
    return msg.header.stamp


def stamp_ros(kind: Kind, msg: Any, stamp_ns: int) -> None:
    """Write ``stamp_ns`` into a ROS message of ``kind`` (Twist has no stamp: linear.x)."""
    if kind.stamp_at == "twist":
        msg.linear.x = stamp_ns / NS
        return
    time_msg = _ros_time(kind, msg)
    time_msg.sec, time_msg.nanosec = divmod(stamp_ns, NS)


def ros_stamp(kind: Kind, msg: Any) -> int:
    """The stamp :func:`stamp_ros` wrote (after a trip through the bridge)."""
    if kind.stamp_at == "twist":
        seconds: float = msg.linear.x
        return round(seconds * NS)
    time_msg = _ros_time(kind, msg)
    return int(time_msg.sec) * NS + int(time_msg.nanosec)


def ros_stamp_cdr(kind: Kind, data: bytes) -> int:
    """The stamp of a serialized ROS message of ``kind``, read without deserializing it: a
    header or a clock is the message's first field, right after the 4-byte encapsulation
    (whose second byte says the byte order)."""
    if kind.stamp_at not in ("header", "clock"):
        msg = f"{kind.name}: the stamp is not the message's first field"
        raise ValueError(msg)
    sec, nanosec = struct.unpack_from("<iI" if data[1] & 1 else ">iI", data, 4)
    return int(sec) * NS + int(nanosec)


def stamp_gz(kind: Kind, msg: Any, stamp_ns: int) -> None:
    """Write ``stamp_ns`` into a Gazebo message of ``kind``."""
    if kind.stamp_at == "twist":
        msg.linear.x = stamp_ns / NS
        return
    time_msg = _gz_time(kind, msg)
    time_msg.sec, time_msg.nsec = divmod(stamp_ns, NS)


def gz_stamp(kind: Kind, msg: Any) -> int:
    """The stamp :func:`stamp_gz` wrote."""
    if kind.stamp_at == "twist":
        seconds: float = msg.linear.x
        return round(seconds * NS)
    time_msg = _gz_time(kind, msg)
    return int(time_msg.sec) * NS + int(time_msg.nsec)


def gz_message(kind: Kind) -> Any:
    """The Gazebo message of ``kind``; an image with the header a gz-sensors camera gives each
    frame: its stamp (simulation time; a flow's publisher writes its send time there), its
    ``frame_id`` and ``seq`` (``CameraSensor::Update``, ``AddSequence``)."""
    msg = kind.pair.to_gz(kind.make_ros())
    if kind.gz_type == "gz.msgs.Image":
        msg.header.stamp.sec, msg.header.stamp.nsec = 12, 345_000_000
        entry = msg.header.data.add()
        entry.key = "seq"
        entry.value.append("1")
    return msg


class GzPayloads:
    """Serialized, stamped Gazebo messages of one kind, cheap for large ones.

    Protobuf merges repeated occurrences of a message field, so for kinds with a top-level
    header the body is serialized once and each payload is ``header bytes + body``.
    """

    def __init__(self, kind: Kind) -> None:
        self.kind = kind
        self._message = gz_message(kind)
        self._body = b""
        if kind.has_header:
            self._message.ClearField("header")
            self._body = self._message.SerializeToString()
            self._stamped = type(self._message)()

    def payload(self, stamp_ns: int) -> bytes:
        if self.kind.has_header:
            stamp_gz(self.kind, self._stamped, stamp_ns)
            return bytes(self._stamped.SerializeToString() + self._body)
        stamp_gz(self.kind, self._message, stamp_ns)
        return bytes(self._message.SerializeToString())
