"""sensor_msgs pairs (docs/conversions-per-package.md §3.5); Image/CameraInfo and
LaserScan/Range/PointCloud2 live in sensor_msgs_image.py and sensor_msgs_scan.py, NavSatFix <->
NavSatWithCovariance (Jetty, not in the C++ bridge) in sensor_msgs_navsat.py.

``sensor_msgs/msg/Imu`` has two Gazebo layouts (docs/protocol-lines.md §9.4): ``gz.msgs.IMU`` is the
Harmonic layout with covariances; ``ignition.msgs.IMU`` is the Fortress layout, whose field
numbers differ and which has no covariances (G→R leaves them zero).

Differences from ros_gz_bridge:
- JointState R→G uses "" / 0.0 where name, velocity or effort is shorter than position
  (C++ reads out of bounds).
- BatteryState with an unknown power_supply_status keeps UNKNOWN (0) without printing.
"""

from __future__ import annotations

from array import array
from typing import Any

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
    PointCloud2,
    Range,
)

from ros_gz_bridge_py.converters._fields import TO_GZ_ONLY, Value, converters, fields, numbers
from ros_gz_bridge_py.converters.covariance import COVARIANCE
from ros_gz_bridge_py.converters.geometry_msgs import QUATERNION, VECTOR3
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.sensor_msgs_image import (
    IMAGE_BULK,
    camera_info_to_gz,
    camera_info_to_ros,
    image_to_gz,
    image_to_ros,
)
from ros_gz_bridge_py.converters.sensor_msgs_navsat import (
    NAV_SAT_POSITION,
    nav_sat_fix_from_gz_nav_sat_with_covariance,
    nav_sat_fix_to_gz_nav_sat_with_covariance,
    new_nav_sat_fix,
)
from ros_gz_bridge_py.converters.sensor_msgs_scan import (
    POINT_CLOUD2_BULK,
    laser_scan_to_gz,
    laser_scan_to_ros,
    point_cloud2_to_gz,
    point_cloud2_to_ros,
    range_to_gz,
    range_to_ros,
)
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.constructors import constructor

GzModel = message_class("gz.msgs.Model")
_new_joint_state = constructor(JointState)


def _known_power_supply_status(status: int) -> int:
    """power_supply_status values exist on both sides with equal numbers (0..4); else UNKNOWN."""
    return status if status in range(5) else 0


_POWER_SUPPLY_STATUS = Value(_known_power_supply_status, _known_power_supply_status)


_BATTERY_STATE = fields(
    ("header", HEADER),
    "voltage",
    "current",
    "charge",
    "capacity",
    "percentage",
    ("power_supply_status", _POWER_SUPPLY_STATUS),
)


def _new_battery_state() -> Any:
    """A BatteryState with what gz does not say: design_capacity NaN (unknown), present true."""
    return BatteryState(design_capacity=float("nan"), present=True)


battery_state_to_gz, battery_state_to_ros = converters(
    _BATTERY_STATE, _new_battery_state, "gz.msgs.BatteryState"
)


fluid_pressure_to_gz, fluid_pressure_to_ros = converters(
    fields(("header", HEADER), ("fluid_pressure", "pressure"), "variance"),
    FluidPressure,
    "gz.msgs.FluidPressure",
)

#: The Fortress layout: the ROS covariances have nowhere to go (G→R they stay zero, as for a
#: missing covariance).
_IMU_FORTRESS = fields(
    ("header", HEADER),
    ("header.frame_id", "entity_name", TO_GZ_ONLY),  # as in C++
    ("orientation", QUATERNION),
    ("angular_velocity", VECTOR3),
    ("linear_acceleration", VECTOR3),
)
#: The Harmonic layout, with the covariances.
_IMU = fields(
    _IMU_FORTRESS,
    ("orientation_covariance", COVARIANCE),
    ("angular_velocity_covariance", COVARIANCE),
    ("linear_acceleration_covariance", COVARIANCE),
)
imu_to_gz, imu_to_ros = converters(_IMU, Imu, "gz.msgs.IMU")
imu_to_gz_fortress, imu_to_ros_fortress = converters(_IMU_FORTRESS, Imu, "ignition.msgs.IMU")


def joint_state_to_gz(ros: Any) -> Any:
    gz = GzModel()
    HEADER.to_gz(ros.header, gz.header)
    names, velocities, efforts = ros.name, ros.velocity, ros.effort
    joints = gz.joint
    for i, position in enumerate(ros.position):
        joint = joints.add(name=names[i] if i < len(names) else "")
        axis = joint.axis1
        axis.position = position
        axis.velocity = velocities[i] if i < len(velocities) else 0.0
        axis.force = efforts[i] if i < len(efforts) else 0.0
    return gz


def joint_state_to_ros(gz: Any) -> Any:
    ros = _new_joint_state()
    HEADER.to_ros(gz.header, ros.header)
    joints = gz.joint
    ros.name = [joint.name for joint in joints]
    ros.position = array("d", [joint.axis1.position for joint in joints])
    ros.velocity = array("d", [joint.axis1.velocity for joint in joints])
    ros.effort = array("d", [joint.axis1.force for joint in joints])
    return ros


joy_to_gz, joy_to_ros = converters(
    fields(("header", HEADER), ("axes", numbers("f")), ("buttons", numbers("i"))),
    Joy,
    "gz.msgs.Joy",
)

#: magnetic_field_covariance has no gz counterpart and is dropped.
magnetic_field_to_gz, magnetic_field_to_ros = converters(
    fields(("header", HEADER), ("magnetic_field", "field_tesla", VECTOR3)),
    MagneticField,
    "gz.msgs.Magnetometer",
)

#: status and covariance are dropped; the velocities are 0.
nav_sat_fix_to_gz, nav_sat_fix_to_ros = converters(
    NAV_SAT_POSITION, new_nav_sat_fix, "gz.msgs.NavSat"
)


PAIRS = (
    Pair.of(BatteryState, "gz.msgs.BatteryState", battery_state_to_gz, battery_state_to_ros),
    Pair.of(CameraInfo, "gz.msgs.CameraInfo", camera_info_to_gz, camera_info_to_ros),
    Pair.of(FluidPressure, "gz.msgs.FluidPressure", fluid_pressure_to_gz, fluid_pressure_to_ros),
    Pair.of(Image, "gz.msgs.Image", image_to_gz, image_to_ros, bulk=IMAGE_BULK),
    Pair.of(Imu, "gz.msgs.IMU", imu_to_gz, imu_to_ros),
    Pair.of(Imu, "ignition.msgs.IMU", imu_to_gz_fortress, imu_to_ros_fortress),
    Pair.of(JointState, "gz.msgs.Model", joint_state_to_gz, joint_state_to_ros),
    Pair.of(Joy, "gz.msgs.Joy", joy_to_gz, joy_to_ros),
    Pair.of(LaserScan, "gz.msgs.LaserScan", laser_scan_to_gz, laser_scan_to_ros),
    Pair.of(MagneticField, "gz.msgs.Magnetometer", magnetic_field_to_gz, magnetic_field_to_ros),
    # gps_msgs/msg/GPSFix pairs with gz.msgs.NavSat too.
    Pair.of(
        NavSatFix,
        "gz.msgs.NavSat",
        nav_sat_fix_to_gz,
        nav_sat_fix_to_ros,
        default_for_gz_type=True,
    ),
    Pair.of(
        NavSatFix,
        "gz.msgs.NavSatWithCovariance",
        nav_sat_fix_to_gz_nav_sat_with_covariance,
        nav_sat_fix_from_gz_nav_sat_with_covariance,
    ),
    Pair.of(
        PointCloud2,
        "gz.msgs.PointCloudPacked",
        point_cloud2_to_gz,
        point_cloud2_to_ros,
        bulk=POINT_CLOUD2_BULK,
    ),
    Pair.of(Range, "gz.msgs.LaserScan", range_to_gz, range_to_ros),
)
