"""The Gazebo -> ROS wire cases of std_msgs, geometry_msgs, nav_msgs, tf2_msgs, sensor_msgs and
rosgraph_msgs: a text a real publisher sends, and the checks of the ROS message it must become
(the sections of docs/conversions.md and docs/conversions-per-package.md in the headings)."""

from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import TransformStamped, Twist, Vector3, Wrench
from nav_msgs.msg import Odometry
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

from tests.interop.wire_case import Case, assert_header, header, octal_bytes, xyz, xyzw

# --- std (docs/conversions-per-package.md §3.2) ---------------------------------------------------

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
    # Fortress layout: 4 is angular_velocity and 5 linear_acceleration (docs/protocol-lines.md
    # §9.4).
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
)  # fmt: skip
