"""Wire-level conversions: bytes made by real Ignition Transport 11 programs, converted by us.

Gazebo to ROS: for one representative pair of each gz package family, a real publisher (the C++
peer's ``pub`` mode, and for two cases also the Debian CLI one-shot ``ign-transport-topic -p``)
sends a message built from a text protobuf with distinctive values. Our ZmqGzNode subscribes raw
with the exact Fortress type string ``ignition.msgs.X``; the bytes are decoded with
``message_class("ignition.msgs.X")``, converted with the registry's pair, and the ROS fields are
checked against ``docs/conversions.md`` (its section numbers are in the checks). The peer
prints the SHA-256 of what it serialized, so each case also proves that the bytes we converted
are exactly the C++ ones.

Of the pairs added for issue 16, LogicalCameraImage and LogPlaybackStatistics are checked here
both ways. AirSpeed, DVLVelocityTracking (Harmonic+) and NavSatWithCovariance (Jetty) are not:
ign-msgs 8 has no such types, so the Fortress peer can neither build nor decode them.

ROS to Gazebo: for a few pairs, our ``to_gz`` output is serialized, published by our ZmqGzNode
under ``ignition.msgs.X`` and printed by the C++ peer's ``echo`` mode (decoded with the Fortress
schema compiled into ign-msgs 8); the printed text is checked for the expected fields and parsed
back into the message we sent.

All deliveries happen once per module, in module-scoped fixtures that run a few publishers at a
time and stop every process they started before the first test runs; each test then checks one
delivery.
"""

from __future__ import annotations

import hashlib
import math
import re
import struct
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import pytest
from actuator_msgs.msg import Actuators
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped, Twist, Vector3, Wrench
from google.protobuf import text_format
from gps_msgs.msg import GPSFix, GPSStatus
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterType, ParameterValue
from ros_gz_interfaces.msg import (
    Contacts,
    Entity,
    Float32Array,
    Light,
    LogicalCameraImage,
    LogicalCameraImageModel,
    LogPlaybackStatistics,
    ParamVec,
    StringVec,
)
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import (
    BatteryState,
    CameraInfo,
    FluidPressure,
    Image,
    Imu,
    JointState,
    Joy,
    LaserScan,
    MagneticField,
    NavSatFix,
    NavSatStatus,
    PointCloud2,
    PointField,
)
from std_msgs.msg import Bool, Float64, String
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory
from vision_msgs.msg import Detection2D

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import create_gz_node
from testing.gzpeer import (
    IGN_TOPIC,
    Inbox,
    PeerProcess,
    peer_binary,
    require_peer,
    start_peer,
    start_process,
    stop_processes,
    unique_name,
)

pytestmark = pytest.mark.peer

#: Publishing processes alive at once (the machine has 2 cores).
PARALLEL = 4
#: How long one publisher may take to deliver before it is retried or given up.
DELIVERY_TIMEOUT = 15.0
#: The CLI publishes once, 800 ms after advertising, and exits as it does: about one message
#: in four never reaches the wire (docs/protocol.md §2.8.7; before our subscribers stayed
#: connected a moment after a publisher's goodbye, two in three were lost): up to 6 one-shots
#: per case, each a fresh publisher process.
CLI_ATTEMPTS = 6
#: After a one-shot CLI exits, how long its message may still be on its way to us.
CLI_GRACE = 1.0
PEER_ATTEMPTS = 2

SEC = 1_700_000_123
NSEC = 456_789_012


def header(frame: str, sec: int = SEC, nsec: int = NSEC, extra: str = "") -> str:
    """A text gz.msgs.Header with a ``seq`` entry first (ignored by the bridge, §1.3)."""
    return (
        f'header {{ stamp {{ sec: {sec} nsec: {nsec} }} data {{ key: "seq" value: "7" }} '
        f'data {{ key: "frame_id" value: "{frame}" }} {extra}}}'
    )


def assert_header(ros: Any, frame: str, sec: int = SEC, nsec: int = NSEC) -> None:
    assert ros.header.frame_id == frame
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (sec, nsec)


def xyz(vector: Any) -> tuple[float, float, float]:
    return (vector.x, vector.y, vector.z)


def xyzw(quaternion: Any) -> tuple[float, float, float, float]:
    return (quaternion.x, quaternion.y, quaternion.z, quaternion.w)


def f32(value: float) -> float:
    """``value`` rounded to float32, as a float32 ROS field holds it."""
    rounded: float = struct.unpack("<f", struct.pack("<f", value))[0]
    return rounded


def octal_bytes(data: bytes) -> str:
    """``data`` as a text-format string literal body (every byte an octal escape)."""
    return "".join(f"\\{byte:03o}" for byte in data)


@dataclass(frozen=True)
class Case:
    """One Gazebo -> ROS conversion: what the real publisher sends and what ROS must get."""

    name: str
    gz_type: str
    ros_type: str
    text: str
    check: Callable[[Any], None]
    #: Also published by the Debian CLI one-shot, not only by the C++ peer.
    cli: bool = False


# --- std (§3.2) -------------------------------------------------------------------------------

STRING_TEXT = 'wire ✓ \\"quoted\\" a::b'


def check_string(ros: Any) -> None:
    assert isinstance(ros, String)
    assert ros.data == 'wire ✓ "quoted" a::b'


def check_double(ros: Any) -> None:
    assert isinstance(ros, Float64)
    assert ros.data == -1234.5678e-3


def check_boolean(ros: Any) -> None:
    assert isinstance(ros, Bool)
    assert ros.data is True


# --- geometry (§1.3, §1.4, §3.3) ----------------------------------------------------------------

POSE_TEXT = (
    header(
        "old_frame",
        extra='data { key: "frame_id" value: "world::robot::base" } '
        'data { key: "frame_id" } data { key: "child_frame_id" value: "ignored" } ',
    )
    + ' name: "ignored_name" id: 5 position { x: 1.5 y: -2.25 z: 3.125 }'
    " orientation { x: 0.1 y: -0.2 z: 0.3 w: 0.9 }"
)


def check_pose_stamped(ros: Any) -> None:
    # The last frame_id entry with a value wins; the one without a value is skipped; `::` -> `/`.
    assert_header(ros, "world/robot/base")
    assert xyz(ros.pose.position) == (1.5, -2.25, 3.125)
    assert xyzw(ros.pose.orientation) == (0.1, -0.2, 0.3, 0.9)


def check_twist(ros: Any) -> None:
    assert isinstance(ros, Twist)
    assert xyz(ros.linear) == (0.5, -0.25, 2.0)
    assert xyz(ros.angular) == (-0.125, 0.0625, 1.75)


def check_wrench(ros: Any) -> None:
    assert isinstance(ros, Wrench)
    assert xyz(ros.force) == (10.5, -20.25, 30.0)
    assert xyz(ros.torque) == (-1.5, 2.5, -3.5)


def check_vector3d(ros: Any) -> None:
    assert isinstance(ros, Vector3)
    assert xyz(ros) == (-7.25, 8.5, 1e-9)


# --- nav (§3.4) ---------------------------------------------------------------------------------


def check_odometry(ros: Any) -> None:
    assert isinstance(ros, Odometry)
    assert_header(ros, "odom")
    # The first child_frame_id entry wins and goes through gz_to_ros_frame.
    assert ros.child_frame_id == "robot/base_link"
    assert xyz(ros.pose.pose.position) == (4.0, 5.0, 6.0)
    assert xyzw(ros.pose.pose.orientation) == (0.0, 0.0, 0.6, 0.8)
    assert xyz(ros.twist.twist.linear) == (1.25, 0.0, 0.0)
    assert xyz(ros.twist.twist.angular) == (0.0, 0.0, -0.5)
    assert list(ros.pose.covariance) == [0.0] * 36
    assert list(ros.twist.covariance) == [0.0] * 36


# --- tf (§3.7) ----------------------------------------------------------------------------------

TF_TEXT = (
    header("top_frame_ignored")
    + " pose { "
    + header("world", 10, 20, 'data { key: "child_frame_id" value: "robot::base" } ')
    + ' name: "robot" position { x: 1 y: 2 z: 3 } orientation { x: 0 y: 0 z: 0 w: 1 } }'
    + " pose { "
    + header("robot::base", 11, 21, 'data { key: "child_frame_id" value: "robot::arm" } ')
    + ' name: "arm" position { x: -1 y: -2 z: -3 } }'
)


def check_tf(ros: Any) -> None:
    assert isinstance(ros, TFMessage)
    assert len(ros.transforms) == 2
    first, second = ros.transforms
    assert isinstance(first, TransformStamped)
    # Each transform takes the pose's own header; the Pose_V header is ignored.
    assert_header(first, "world", 10, 20)
    assert first.child_frame_id == "robot/base"
    assert xyz(first.transform.translation) == (1.0, 2.0, 3.0)
    assert xyzw(first.transform.rotation) == (0.0, 0.0, 0.0, 1.0)
    assert_header(second, "robot/base", 11, 21)
    assert second.child_frame_id == "robot/arm"
    assert xyz(second.transform.translation) == (-1.0, -2.0, -3.0)
    # No orientation on the wire: proto3 w defaults to 0, not the ROS identity (§1.4 pitfall).
    assert xyzw(second.transform.rotation) == (0.0, 0.0, 0.0, 0.0)


# --- sensors (§3.5, §3.8) -----------------------------------------------------------------------


def check_imu_fortress(ros: Any) -> None:
    assert isinstance(ros, Imu)
    assert_header(ros, "imu/link")
    assert xyzw(ros.orientation) == (0.5, -0.5, 0.5, -0.5)
    # Fortress layout: 4 is angular_velocity and 5 linear_acceleration (docs/protocol.md §9.4).
    assert xyz(ros.angular_velocity) == (0.25, -0.125, 3.5)
    assert xyz(ros.linear_acceleration) == (0.5, 0.75, -9.81)
    # No covariances exist in the Fortress layout: all stay zero (§3.5 Imu, §1.5).
    assert list(ros.orientation_covariance) == [0.0] * 9
    assert list(ros.angular_velocity_covariance) == [0.0] * 9
    assert list(ros.linear_acceleration_covariance) == [0.0] * 9


LASER_TEXT = (
    header("header_frame_overwritten") + ' frame: "lidar::link" world_pose { position { x: 9 } }'
    " angle_min: -0.5 angle_max: 0.5 angle_step: 0.5 range_min: 0.125 range_max: 30"
    " count: 3 vertical_angle_min: -0.25 vertical_angle_max: 0.25 vertical_angle_step: 0.5"
    " vertical_count: 2"
    " ranges: [1, 2, 3, 4.5, 5.5, 6.5] intensities: [10, 20, 30, 40, 50, 60]"
)


def check_laser_scan(ros: Any) -> None:
    assert isinstance(ros, LaserScan)
    # header.frame_id is overwritten by gz `frame`, through gz_to_ros_frame.
    assert_header(ros, "lidar/link")
    assert (ros.angle_min, ros.angle_max, ros.angle_increment) == (-0.5, 0.5, 0.5)
    assert (ros.range_min, ros.range_max) == (0.125, 30.0)
    assert (ros.time_increment, ros.scan_time) == (0.0, 0.0)
    # vertical_count 2: start = (2 // 2) * count, i.e. the second row.
    assert list(ros.ranges) == [4.5, 5.5, 6.5]
    assert list(ros.intensities) == [40.0, 50.0, 60.0]


IMAGE_DATA = bytes((7 * i + 3) % 256 for i in range(4 * 3 * 3))


def check_image(ros: Any) -> None:
    assert isinstance(ros, Image)
    assert_header(ros, "camera/optical")
    assert (ros.width, ros.height) == (4, 3)
    assert ros.encoding == "rgb8"
    # step is width * 3 * 1, whatever gz `step` says; is_bigendian is always 0.
    assert ros.step == 12
    assert ros.is_bigendian == 0
    assert bytes(ros.data) == IMAGE_DATA


CAMERA_D = (-0.25, 0.125, 0.001, -0.002, 0.5, 0.0625, -0.03125, 0.015625)
CAMERA_K = (525.5, 0.0, 319.5, 0.0, 526.25, 239.5, 0.0, 0.0, 1.0)
CAMERA_P = (525.5, 0.0, 319.5, -10.0, 0.0, 526.25, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0)
CAMERA_R = (1.0, 0.0, 0.0, 0.0, 0.5, -0.5, 0.0, 0.5, 0.5)


def floats(values: Sequence[float]) -> str:
    return "[" + ", ".join(repr(v) for v in values) + "]"


def check_camera_info(ros: Any) -> None:
    assert isinstance(ros, CameraInfo)
    assert_header(ros, "camera")
    assert (ros.width, ros.height) == (640, 480)
    assert ros.distortion_model == "rational_polynomial"
    assert tuple(ros.d) == CAMERA_D
    assert tuple(ros.k) == CAMERA_K
    assert tuple(ros.p) == CAMERA_P
    assert tuple(ros.r) == CAMERA_R
    assert (ros.binning_x, ros.binning_y) == (0, 0)


def check_navsat(ros: Any) -> None:
    assert isinstance(ros, NavSatFix)
    # header.frame_id is overwritten by gz `frame_id`, through gz_to_ros_frame.
    assert_header(ros, "gps/link")
    assert (ros.latitude, ros.longitude, ros.altitude) == (48.8566, 2.3522, 35.5)
    assert ros.status.status == NavSatStatus.STATUS_FIX
    assert ros.status.service == 0
    assert ros.position_covariance_type == NavSatFix.COVARIANCE_TYPE_UNKNOWN
    assert list(ros.position_covariance) == [0.0] * 9


def check_joint_state(ros: Any) -> None:
    assert isinstance(ros, JointState)
    assert_header(ros, "arm")
    assert list(ros.name) == ["shoulder", "elbow"]
    assert list(ros.position) == [0.5, -1.25]
    assert list(ros.velocity) == [-1.5, 0.0]
    assert list(ros.effort) == [2.5, 0.0]


CLOUD_DATA = struct.pack("<fHxxfHxx", 1.5, 7, -2.5, 65535)


def check_point_cloud(ros: Any) -> None:
    assert isinstance(ros, PointCloud2)
    assert_header(ros, "lidar")
    assert [(f.name, f.offset, f.datatype, f.count) for f in ros.fields] == [
        ("x", 0, PointField.FLOAT32, 1),
        ("intensity", 4, PointField.UINT16, 1),
    ]
    assert (ros.height, ros.width, ros.point_step, ros.row_step) == (1, 2, 8, 16)
    assert ros.is_bigendian is False
    assert ros.is_dense is True
    assert bytes(ros.data) == CLOUD_DATA


def check_clock(ros: Any) -> None:
    assert isinstance(ros, Clock)
    # Only `sim` is read, normalised: 41 s + 1.5e9 ns = 42.5 s (§3.8).
    assert (ros.clock.sec, ros.clock.nanosec) == (42, 500_000_000)


def check_battery(ros: Any) -> None:
    assert isinstance(ros, BatteryState)
    assert_header(ros, "battery")
    assert (ros.voltage, ros.current, ros.charge, ros.capacity) == (12.5, -1.25, 3.5, 5.0)
    assert ros.percentage == 0.75
    assert ros.power_supply_status == BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
    assert math.isnan(ros.design_capacity)
    assert ros.power_supply_health == BatteryState.POWER_SUPPLY_HEALTH_UNKNOWN
    assert ros.power_supply_technology == BatteryState.POWER_SUPPLY_TECHNOLOGY_UNKNOWN
    assert ros.present is True
    assert ros.temperature == 0.0
    assert list(ros.cell_voltage) == []
    assert list(ros.cell_temperature) == []


def check_fluid_pressure(ros: Any) -> None:
    assert isinstance(ros, FluidPressure)
    # Header stamps are not normalised: nsec >= 1e9 is kept (§1.2).
    assert_header(ros, "baro", 12, 1_500_000_000)
    assert (ros.fluid_pressure, ros.variance) == (101325.5, 0.25)


def check_magnetometer(ros: Any) -> None:
    assert isinstance(ros, MagneticField)
    assert_header(ros, "mag")
    assert xyz(ros.magnetic_field) == (2.1e-5, -4.5e-6, 4.3e-5)
    assert list(ros.magnetic_field_covariance) == [0.0] * 9


def check_joy(ros: Any) -> None:
    assert isinstance(ros, Joy)
    assert_header(ros, "joy")
    assert list(ros.axes) == [0.5, -1.0, 0.25]
    assert list(ros.buttons) == [1, 0, 1, -7]


# --- ros_gz_interfaces (§3.13) ------------------------------------------------------------------


def check_entity(ros: Any) -> None:
    assert isinstance(ros, Entity)
    assert ros.id == 123_456_789_012
    assert ros.name == "box::link"
    assert ros.type == Entity.LINK


CONTACTS_TEXT = (
    header("world") + " contact {"
    ' collision1 { id: 11 name: "box::link::collision" type: COLLISION }'
    ' collision2 { id: 22 name: "ground::link::collision" type: COLLISION }'
    " position { x: 1 y: 2 z: 0 } position { x: 1.5 y: 2.5 z: 0 }"
    " normal { x: 0 y: 0 z: 1 }"
    " depth: 0.01 depth: 0.02"
    " wrench { "
    + header("contact", 3, 4)
    + ' body_1_name: "box" body_1_id: 11 body_2_name: "ground" body_2_id: 22'
    " body_1_wrench { force { x: 0.5 y: 0 z: -9.5 } torque { x: 0.25 y: 0 z: 0 } }"
    " body_2_wrench { force { x: -0.5 y: 0 z: 9.5 } torque { x: 0 y: -0.25 z: 0 } } }"
    ' world { id: 1 name: "default" type: MODEL } }'
)


def check_contacts(ros: Any) -> None:
    assert isinstance(ros, Contacts)
    assert_header(ros, "world")
    assert len(ros.contacts) == 1
    contact = ros.contacts[0]
    assert (contact.collision1.id, contact.collision1.name, contact.collision1.type) == (
        11,
        "box::link::collision",
        Entity.COLLISION,
    )
    assert (contact.collision2.id, contact.collision2.name) == (22, "ground::link::collision")
    assert [xyz(p) for p in contact.positions] == [(1.0, 2.0, 0.0), (1.5, 2.5, 0.0)]
    assert [xyz(n) for n in contact.normals] == [(0.0, 0.0, 1.0)]
    assert list(contact.depths) == [0.01, 0.02]
    assert len(contact.wrenches) == 1
    wrench = contact.wrenches[0]
    assert_header(wrench, "contact", 3, 4)
    assert (wrench.body_1_name.data, wrench.body_1_id.data) == ("box", 11)
    assert (wrench.body_2_name.data, wrench.body_2_id.data) == ("ground", 22)
    assert xyz(wrench.body_1_wrench.force) == (0.5, 0.0, -9.5)
    assert xyz(wrench.body_1_wrench.torque) == (0.25, 0.0, 0.0)
    assert xyz(wrench.body_2_wrench.force) == (-0.5, 0.0, 9.5)
    assert xyz(wrench.body_2_wrench.torque) == (0.0, -0.25, 0.0)


LIGHT_TEXT = (
    header("lights") + ' name: "spot::lamp" type: SPOT'
    " pose { position { x: 1 y: 2 z: 3 } orientation { x: 0 y: 0 z: 0 w: 1 } }"
    " diffuse { r: 0.25 g: 0.5 b: 0.75 a: 1 } specular { r: 0.125 g: 0.25 b: 0.5 a: 0.75 }"
    " attenuation_constant: 0.5 attenuation_linear: 0.25 attenuation_quadratic: 0.125"
    " direction { x: 0 y: 0.5 z: -1 } range: 20 cast_shadows: true"
    " spot_inner_angle: 0.5 spot_outer_angle: 1 spot_falloff: 2"
    " id: 7 parent_id: 3 intensity: 1.5"
)


def check_light(ros: Any) -> None:
    assert isinstance(ros, Light)
    assert_header(ros, "lights")
    assert ros.name == "spot::lamp"
    assert ros.type == Light.SPOT
    assert xyz(ros.pose.position) == (1.0, 2.0, 3.0)
    assert xyzw(ros.pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    assert (ros.diffuse.r, ros.diffuse.g, ros.diffuse.b, ros.diffuse.a) == (0.25, 0.5, 0.75, 1.0)
    specular = (ros.specular.r, ros.specular.g, ros.specular.b, ros.specular.a)
    assert specular == (0.125, 0.25, 0.5, 0.75)
    attenuation = (ros.attenuation_constant, ros.attenuation_linear, ros.attenuation_quadratic)
    assert attenuation == (0.5, 0.25, 0.125)
    assert xyz(ros.direction) == (0.0, 0.5, -1.0)
    assert (ros.range, ros.cast_shadows) == (20.0, True)
    assert (ros.spot_inner_angle, ros.spot_outer_angle, ros.spot_falloff) == (0.5, 1.0, 2.0)
    assert (ros.id, ros.parent_id, ros.intensity) == (7, 3, 1.5)


PARAM_TEXT = (
    header("params") + ' params { key: "b_int" value { type: INT32 int_value: -7 } }'
    ' params { key: "a_str" value { type: STRING string_value: "x y" } }'
    " children { "
    + header("child_header_ignored")
    + ' params { key: "flag" value { type: BOOLEAN bool_value: true } } }'
)


def check_param(ros: Any) -> None:
    assert isinstance(ros, ParamVec)
    assert_header(ros, "params")
    names = [p.name for p in ros.params]
    # Map entries first (their order is unspecified), then each child with `child_<c>/`.
    assert sorted(names[:2]) == ["a_str", "b_int"]
    assert names[2:] == ["child_0/flag"]
    values = {p.name: p.value for p in ros.params}
    assert (values["b_int"].type, values["b_int"].integer_value) == (
        ParameterType.PARAMETER_INTEGER,
        -7,
    )
    assert (values["a_str"].type, values["a_str"].string_value) == (
        ParameterType.PARAMETER_STRING,
        "x y",
    )
    flag = values["child_0/flag"]
    assert (flag.type, flag.bool_value) == (ParameterType.PARAMETER_BOOL, True)


def check_string_v(ros: Any) -> None:
    assert isinstance(ros, StringVec)
    assert_header(ros, "strings")
    assert list(ros.data) == ["first", "b::c", "", "ünïcode"]


def check_float_v(ros: Any) -> None:
    assert isinstance(ros, Float32Array)
    assert list(ros.data) == [1.5, -2.25, 1024.0, f32(0.1)]


LOGICAL_CAMERA_TEXT = (
    header("robot::camera")
    + " pose { position { x: 1.5 y: -2.5 z: 0.75 } orientation { x: 0 y: 0 z: 0.6 w: 0.8 } }"
    ' model { name: "cone::yellow" pose { position { x: 4 y: 5 z: 6 } orientation { w: 1 } } }'
    ' model { name: "box" pose { position { x: -7 } } }'
)


def check_logical_camera(ros: Any) -> None:
    assert isinstance(ros, LogicalCameraImage)
    assert_header(ros, "robot/camera")
    assert xyz(ros.pose.position) == (1.5, -2.5, 0.75)
    assert xyzw(ros.pose.orientation) == (0.0, 0.0, 0.6, 0.8)
    # Model names are names, not frames: `::` stays.
    assert [model.name for model in ros.model] == ["cone::yellow", "box"]
    assert xyz(ros.model[0].pose.position) == (4.0, 5.0, 6.0)
    assert xyzw(ros.model[0].pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    assert xyz(ros.model[1].pose.position) == (-7.0, 0.0, 0.0)
    # No orientation on the wire: proto3 w defaults to 0 (§1.4 pitfall).
    assert xyzw(ros.model[1].pose.orientation) == (0.0, 0.0, 0.0, 0.0)


def check_log_playback(ros: Any) -> None:
    assert isinstance(ros, LogPlaybackStatistics)
    assert_header(ros, "log")
    assert (ros.start_time.sec, ros.start_time.nanosec) == (1_700_000_000, 5)
    assert (ros.end_time.sec, ros.end_time.nanosec) == (1_700_000_360, 999_999_999)


# --- vision, gps, actuators, trajectory, rcl (§3.6, §3.9-§3.12) ----------------------------------


def check_detection_2d(ros: Any) -> None:
    assert isinstance(ros, Detection2D)
    assert_header(ros, "camera")
    assert len(ros.results) == 1
    hypothesis = ros.results[0].hypothesis
    assert (hypothesis.class_id, hypothesis.score) == ("42", 1.0)
    assert xyzw(ros.results[0].pose.pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    center = ros.bbox.center
    assert (center.position.x, center.position.y, center.theta) == (3.0, 4.0, 0.0)
    assert (ros.bbox.size_x, ros.bbox.size_y) == (2.0, 4.0)
    assert ros.id == ""


def check_gps_fix(ros: Any) -> None:
    assert isinstance(ros, GPSFix)
    assert_header(ros, "gps/antenna")
    assert (ros.latitude, ros.longitude, ros.altitude) == (-33.8688, 151.2093, 58.25)
    # speed/track from the ENU velocity, track in radians from East (§3.6).
    assert ros.speed == 5.0
    assert ros.track == math.atan2(4.0, 3.0)
    assert ros.climb == -0.5
    assert ros.status.status == GPSStatus.STATUS_GBAS_FIX
    assert ros.position_covariance_type == GPSFix.COVARIANCE_TYPE_UNKNOWN
    assert list(ros.position_covariance) == [0.0] * 9


def check_actuators(ros: Any) -> None:
    assert isinstance(ros, Actuators)
    assert_header(ros, "base")
    assert list(ros.position) == [0.5, -0.5]
    assert list(ros.velocity) == [100.25, 200.5, -300.75]
    assert list(ros.normalized) == [0.125]


def check_joint_trajectory(ros: Any) -> None:
    assert isinstance(ros, JointTrajectory)
    assert_header(ros, "arm_base")
    assert list(ros.joint_names) == ["joint_1", "joint_2"]
    assert len(ros.points) == 2
    first, second = ros.points
    assert (list(first.positions), list(first.velocities)) == ([0.5, 1.5], [])
    assert (list(first.accelerations), list(first.effort)) == ([0.25], [4.0, 5.0])
    # time_from_start is normalised (§3.9): 3 s + 1.25e9 ns = 4.25 s. nsec is first read as
    # uint32, so -0.25e9 ns counts as 4044967296 ns: 2 s + that = 6.044967296 s.
    assert first.time_from_start.sec == 4
    assert first.time_from_start.nanosec == 250_000_000
    assert list(second.positions) == [-0.5, -1.5]
    assert (second.time_from_start.sec, second.time_from_start.nanosec) == (6, 44_967_296)


def check_any(ros: Any) -> None:
    assert isinstance(ros, ParameterValue)
    assert ros.type == ParameterType.PARAMETER_DOUBLE
    assert ros.double_value == 2.718281828
    assert (ros.integer_value, ros.string_value, ros.bool_value) == (0, "", False)


CASES = (
    Case("string", "ignition.msgs.StringMsg", "std_msgs/msg/String",
         header("ignored") + f' data: "{STRING_TEXT}"', check_string, cli=True),
    Case("double", "ignition.msgs.Double", "std_msgs/msg/Float64",
         "data: -1234.5678e-3", check_double),
    Case("boolean", "ignition.msgs.Boolean", "std_msgs/msg/Bool", "data: true", check_boolean),
    Case("pose_stamped", "ignition.msgs.Pose", "geometry_msgs/msg/PoseStamped",
         POSE_TEXT, check_pose_stamped, cli=True),
    Case("twist", "ignition.msgs.Twist", "geometry_msgs/msg/Twist",
         header("ignored") + " linear { x: 0.5 y: -0.25 z: 2 }"
         " angular { x: -0.125 y: 0.0625 z: 1.75 }", check_twist),
    Case("wrench", "ignition.msgs.Wrench", "geometry_msgs/msg/Wrench",
         "force { x: 10.5 y: -20.25 z: 30 } torque { x: -1.5 y: 2.5 z: -3.5 }"
         " force_offset { x: 99 y: 99 z: 99 }", check_wrench),
    Case("vector3d", "ignition.msgs.Vector3d", "geometry_msgs/msg/Vector3",
         "x: -7.25 y: 8.5 z: 1e-9", check_vector3d),
    Case("odometry", "ignition.msgs.Odometry", "nav_msgs/msg/Odometry",
         header("odom", extra='data { key: "child_frame_id" value: "robot::base_link" } '
                'data { key: "child_frame_id" value: "second" } ')
         + " pose { position { x: 4 y: 5 z: 6 } orientation { x: 0 y: 0 z: 0.6 w: 0.8 } }"
         " twist { linear { x: 1.25 } angular { z: -0.5 } }", check_odometry),
    Case("tf", "ignition.msgs.Pose_V", "tf2_msgs/msg/TFMessage", TF_TEXT, check_tf),
    Case("imu", "ignition.msgs.IMU", "sensor_msgs/msg/Imu",
         header("imu::link") + ' entity_name: "model::imu"'
         " orientation { x: 0.5 y: -0.5 z: 0.5 w: -0.5 }"
         " angular_velocity { x: 0.25 y: -0.125 z: 3.5 }"
         " linear_acceleration { x: 0.5 y: 0.75 z: -9.81 }", check_imu_fortress),
    Case("laser_scan", "ignition.msgs.LaserScan", "sensor_msgs/msg/LaserScan",
         LASER_TEXT, check_laser_scan),
    Case("image", "ignition.msgs.Image", "sensor_msgs/msg/Image",
         header("camera::optical") + " width: 4 height: 3 step: 99"
         f' data: "{octal_bytes(IMAGE_DATA)}" pixel_format_type: RGB_INT8', check_image),
    Case("camera_info", "ignition.msgs.CameraInfo", "sensor_msgs/msg/CameraInfo",
         header("camera") + " width: 640 height: 480"
         f" distortion {{ model: RATIONAL_POLYNOMIAL k: {floats(CAMERA_D)} }}"
         f" intrinsics {{ k: {floats(CAMERA_K)} }} projection {{ p: {floats(CAMERA_P)} }}"
         f" rectification_matrix: {floats(CAMERA_R)}", check_camera_info),
    Case("navsat", "ignition.msgs.NavSat", "sensor_msgs/msg/NavSatFix",
         header("overwritten") + " latitude_deg: 48.8566 longitude_deg: 2.3522 altitude: 35.5"
         ' velocity_east: 1 velocity_north: 2 velocity_up: 3 frame_id: "gps::link"',
         check_navsat),
    Case("joint_state", "ignition.msgs.Model", "sensor_msgs/msg/JointState",
         header("arm") + ' name: "robot_arm" id: 9'
         ' joint { name: "shoulder" axis1 { position: 0.5 velocity: -1.5 force: 2.5 }'
         " axis2 { position: 99 } }"
         ' joint { name: "elbow" axis1 { position: -1.25 } }', check_joint_state),
    Case("point_cloud", "ignition.msgs.PointCloudPacked", "sensor_msgs/msg/PointCloud2",
         header("lidar") + ' field { name: "x" offset: 0 datatype: FLOAT32 count: 1 }'
         ' field { name: "intensity" offset: 4 datatype: UINT16 count: 1 }'
         " height: 1 width: 2 is_bigendian: false point_step: 8 row_step: 16"
         f' data: "{octal_bytes(CLOUD_DATA)}" is_dense: true', check_point_cloud),
    Case("clock", "ignition.msgs.Clock", "rosgraph_msgs/msg/Clock",
         header("clock") + " system { sec: 1 nsec: 2 } real { sec: 3 nsec: 4 }"
         " sim { sec: 41 nsec: 1500000000 }", check_clock),
    Case("battery", "ignition.msgs.BatteryState", "sensor_msgs/msg/BatteryState",
         header("battery") + " voltage: 12.5 current: -1.25 charge: 3.5 capacity: 5"
         " percentage: 0.75 power_supply_status: DISCHARGING", check_battery),
    Case("fluid_pressure", "ignition.msgs.FluidPressure", "sensor_msgs/msg/FluidPressure",
         header("baro", 12, 1_500_000_000) + " pressure: 101325.5 variance: 0.25",
         check_fluid_pressure),
    Case("magnetometer", "ignition.msgs.Magnetometer", "sensor_msgs/msg/MagneticField",
         header("mag") + " field_tesla { x: 2.1e-5 y: -4.5e-6 z: 4.3e-5 }", check_magnetometer),
    Case("joy", "ignition.msgs.Joy", "sensor_msgs/msg/Joy",
         header("joy") + " axes: [0.5, -1, 0.25] buttons: [1, 0, 1, -7]", check_joy),
    Case("entity", "ignition.msgs.Entity", "ros_gz_interfaces/msg/Entity",
         'id: 123456789012 name: "box::link" type: LINK', check_entity),
    Case("contacts", "ignition.msgs.Contacts", "ros_gz_interfaces/msg/Contacts",
         CONTACTS_TEXT, check_contacts),
    Case("light", "ignition.msgs.Light", "ros_gz_interfaces/msg/Light", LIGHT_TEXT, check_light),
    Case("param", "ignition.msgs.Param", "ros_gz_interfaces/msg/ParamVec",
         PARAM_TEXT, check_param),
    Case("string_v", "ignition.msgs.StringMsg_V", "ros_gz_interfaces/msg/StringVec",
         header("strings") + ' data: ["first", "b::c", "", "ünïcode"]', check_string_v),
    Case("float_v", "ignition.msgs.Float_V", "ros_gz_interfaces/msg/Float32Array",
         header("ignored") + " data: [1.5, -2.25, 1024, 0.1]", check_float_v),
    Case("logical_camera", "ignition.msgs.LogicalCameraImage",
         "ros_gz_interfaces/msg/LogicalCameraImage", LOGICAL_CAMERA_TEXT, check_logical_camera),
    Case("log_playback", "ignition.msgs.LogPlaybackStatistics",
         "ros_gz_interfaces/msg/LogPlaybackStatistics",
         header("log") + " start_time { sec: 1700000000 nsec: 5 }"
         " end_time { sec: 1700000360 nsec: 999999999 }", check_log_playback),
    Case("detection_2d", "ignition.msgs.AnnotatedAxisAligned2DBox",
         "vision_msgs/msg/Detection2D",
         header("camera") + " box { min_corner { x: 2 y: 2 } max_corner { x: 4 y: 6 } }"
         " label: 42", check_detection_2d),
    Case("gps_fix", "ignition.msgs.NavSat", "gps_msgs/msg/GPSFix",
         header("overwritten") + " latitude_deg: -33.8688 longitude_deg: 151.2093"
         ' altitude: 58.25 velocity_east: 3 velocity_north: 4 velocity_up: -0.5'
         ' frame_id: "gps::antenna"', check_gps_fix),
    Case("actuators", "ignition.msgs.Actuators", "actuator_msgs/msg/Actuators",
         header("base") + " position: [0.5, -0.5] velocity: [100.25, 200.5, -300.75]"
         " normalized: [0.125]", check_actuators),
    Case("joint_trajectory", "ignition.msgs.JointTrajectory",
         "trajectory_msgs/msg/JointTrajectory",
         header("arm_base") + ' joint_names: ["joint_1", "joint_2"]'
         " points { positions: [0.5, 1.5] accelerations: [0.25] effort: [4, 5]"
         " time_from_start { sec: 3 nsec: 1250000000 } }"
         " points { positions: [-0.5, -1.5] time_from_start { sec: 2 nsec: -250000000 } }",
         check_joint_trajectory),
    Case("any", "ignition.msgs.Any", "rcl_interfaces/msg/ParameterValue",
         "type: DOUBLE double_value: 2.718281828", check_any),
)  # fmt: skip

#: (case, source) for every delivery: each case from the C++ peer, some also from the CLI.
DELIVERIES = [(case, "peer") for case in CASES] + [(c, "cli") for c in CASES if c.cli]


@dataclass
class Delivery:
    """What one publisher delivered to our raw subscriber."""

    payload: bytes | None = None
    msg_type: str = ""
    #: The peer's ``PAYLOAD sha256=.. len=..`` digest of what it serialized ("" for the CLI).
    peer_digest: str = ""
    log: list[str] = field(default_factory=list)


class _Publishing:
    """One (case, source) delivery in flight: our subscription plus the real publisher."""

    def __init__(self, node: Any, case: Case, source: str) -> None:
        self.case = case
        self.source = source
        self.topic = unique_name(f"wire_{case.name}_{source}")
        self.inbox = Inbox()
        self.subscription = node.subscribe(self.topic, self.inbox, msg_type=case.gz_type)
        self.result = Delivery()
        self.attempts = 0
        self.proc: PeerProcess | None = None
        self.started = 0.0
        self.exited = 0.0

    def start(self) -> None:
        self.attempts += 1
        self.started = time.monotonic()
        self.exited = 0.0
        if self.source == "peer":
            args = ("pub", self.topic, self.case.gz_type, "20", "0", self.case.text)
            self.proc = start_peer(*args, "--wait", "10", "--linger", "0")
        else:
            command = [str(IGN_TOPIC), "-t", self.topic, "-m", self.case.gz_type]
            self.proc = start_process([*command, "-p", self.case.text])

    def _stop(self) -> None:
        assert self.proc is not None
        self.proc.stop()
        self.result.log.append(f"attempt {self.attempts}: {self.proc.args!r}\n{self.proc.output()}")

    def step(self) -> bool:
        """Advance; True once finished (delivered, or out of attempts)."""
        assert self.proc is not None
        items = self.inbox.items()
        now = time.monotonic()
        if items:
            payload, info = items[0]
            self._stop()
            self.result.payload = bytes(payload)
            self.result.msg_type = info.msg_type
            digest = re.search(r"^PAYLOAD (sha256=\w+ len=\d+)$", self.proc.output(), re.M)
            self.result.peer_digest = digest.group(1) if digest else ""
            self.subscription.close()
            return True
        if self.proc.poll() is not None and not self.exited:
            self.exited = now
        grace_over = self.exited and now - self.exited > CLI_GRACE
        if not grace_over and now - self.started < DELIVERY_TIMEOUT:
            return False
        self._stop()
        if self.attempts < (PEER_ATTEMPTS if self.source == "peer" else CLI_ATTEMPTS):
            self.start()
            return False
        self.subscription.close()
        return True


def run_limited(jobs: Sequence[Any], parallel: int) -> None:
    """Run ``jobs`` (``start()``, ``step() -> finished``) with at most ``parallel`` alive."""
    waiting = deque(jobs)
    running: list[Any] = []
    while waiting or running:
        while waiting and len(running) < parallel:
            job = waiting.popleft()
            job.start()
            running.append(job)
        running = [job for job in running if not job.step()]
        time.sleep(0.02)


@pytest.fixture(scope="module")
def gz_node() -> Iterator[Any]:
    """One node of ours for the whole module (overrides the per-test one of conftest)."""
    require_peer()
    with create_gz_node() as node:
        yield node


@pytest.fixture(scope="module")
def deliveries(gz_node: Any) -> dict[tuple[str, str], Delivery]:
    """Every (case name, source) delivery, made once; all processes stopped before return."""
    peer_binary()
    jobs = [_Publishing(gz_node, case, source) for case, source in DELIVERIES]
    try:
        run_limited(jobs, PARALLEL)
    finally:
        stop_processes()
    return {(job.case.name, job.source): job.result for job in jobs}


@pytest.mark.parametrize(
    ("case", "source"),
    DELIVERIES,
    ids=[f"{case.name}-{source}" for case, source in DELIVERIES],
)
def test_real_publisher_bytes_convert_to_the_expected_ros_message(
    case: Case, source: str, deliveries: dict[tuple[str, str], Delivery]
) -> None:
    delivery = deliveries[case.name, source]
    assert delivery.payload is not None, "nothing arrived:\n" + "\n".join(delivery.log)
    assert delivery.msg_type == case.gz_type
    if source == "peer":
        sha = hashlib.sha256(delivery.payload).hexdigest()
        assert delivery.peer_digest == f"sha256={sha} len={len(delivery.payload)}"

    gz_msg = message_class(case.gz_type).FromString(delivery.payload)
    pair = default_registry().get(case.ros_type, case.gz_type)
    ros = pair.to_ros(gz_msg)

    assert isinstance(ros, pair.ros_class)
    case.check(ros)


# --- ROS -> Gazebo: our to_gz bytes printed by the C++ echo ------------------------------------


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
        # count = trunc((max - min) / increment) = 4: the last sample is dropped (§3.5).
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
def echoes(gz_node: Any) -> dict[str, _Echoing]:
    """Every reverse case delivered to the C++ echo once; all processes stopped before return."""
    peer_binary()
    jobs = [_Echoing(gz_node, reverse) for reverse in REVERSES]
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
