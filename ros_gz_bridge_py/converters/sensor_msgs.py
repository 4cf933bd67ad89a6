"""sensor_msgs pairs (conversions.md §3.5); Image/CameraInfo and LaserScan/Range/PointCloud2
live in sensor_msgs_image.py and sensor_msgs_scan.py, NavSatFix <-> NavSatWithCovariance (Jetty,
not in the C++ bridge) in sensor_msgs_navsat.py.

``sensor_msgs/msg/Imu`` has two Gazebo layouts (gz-msgs-versions.md): ``gz.msgs.IMU`` is the
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
    NavSatStatus,
    PointCloud2,
    Range,
)

from ros_gz_bridge_py.bulk.path import BulkPath
from ros_gz_bridge_py.converters.geometry_msgs import (
    covariance_to_ros,
    fill_gz_covariance,
    fill_gz_quaternion,
    fill_gz_vector3,
    fill_ros_quaternion,
    fill_ros_vector3,
)
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.sensor_msgs_image import (
    IMAGE_BULK,
    camera_info_to_gz,
    camera_info_to_ros,
    image_to_gz,
    image_to_ros,
)
from ros_gz_bridge_py.converters.sensor_msgs_navsat import (
    nav_sat_fix_from_gz_nav_sat_with_covariance,
    nav_sat_fix_to_gz_nav_sat_with_covariance,
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
from ros_gz_bridge_py.converters.std_msgs import fill_gz_header, fill_ros_header, gz_to_ros_frame
from ros_gz_bridge_py.msgs import message_class

GzBatteryState = message_class("gz.msgs.BatteryState")
GzFluidPressure = message_class("gz.msgs.FluidPressure")
GzImu = message_class("gz.msgs.IMU")
GzImuFortress = message_class("ignition.msgs.IMU")
GzModel = message_class("gz.msgs.Model")
GzJoy = message_class("gz.msgs.Joy")
GzMagnetometer = message_class("gz.msgs.Magnetometer")
GzNavSat = message_class("gz.msgs.NavSat")

IMU_COVARIANCE_SIZE = 9
#: power_supply_status values that exist on both sides (the numbers are equal).
_POWER_SUPPLY_STATUSES = range(5)


def battery_state_to_gz(ros: Any) -> Any:
    gz = GzBatteryState()
    fill_gz_header(ros.header, gz.header)
    gz.voltage = ros.voltage
    gz.current = ros.current
    gz.charge = ros.charge
    gz.capacity = ros.capacity
    gz.percentage = ros.percentage
    status = ros.power_supply_status
    gz.power_supply_status = status if status in _POWER_SUPPLY_STATUSES else 0
    return gz


def battery_state_to_ros(gz: Any) -> Any:
    ros = BatteryState()
    fill_ros_header(gz.header, ros.header)
    ros.voltage = gz.voltage
    ros.current = gz.current
    ros.charge = gz.charge
    ros.capacity = gz.capacity
    ros.percentage = gz.percentage
    ros.design_capacity = float("nan")
    status = gz.power_supply_status
    ros.power_supply_status = status if status in _POWER_SUPPLY_STATUSES else 0
    ros.present = True
    return ros


def fluid_pressure_to_gz(ros: Any) -> Any:
    gz = GzFluidPressure(pressure=ros.fluid_pressure, variance=ros.variance)
    fill_gz_header(ros.header, gz.header)
    return gz


def fluid_pressure_to_ros(gz: Any) -> Any:
    ros = FluidPressure(fluid_pressure=gz.pressure, variance=gz.variance)
    fill_ros_header(gz.header, ros.header)
    return ros


def _fill_gz_imu_motion(ros: Any, gz: Any) -> None:
    """Fields both layouts share; ``entity_name`` is the frame_id, as in C++."""
    fill_gz_header(ros.header, gz.header)
    gz.entity_name = ros.header.frame_id
    fill_gz_quaternion(ros.orientation, gz.orientation)
    fill_gz_vector3(ros.angular_velocity, gz.angular_velocity)
    fill_gz_vector3(ros.linear_acceleration, gz.linear_acceleration)


def _fill_ros_imu_motion(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    fill_ros_quaternion(gz.orientation, ros.orientation)
    fill_ros_vector3(gz.angular_velocity, ros.angular_velocity)
    fill_ros_vector3(gz.linear_acceleration, ros.linear_acceleration)


def imu_to_gz(ros: Any) -> Any:
    gz = GzImu()
    _fill_gz_imu_motion(ros, gz)
    fill_gz_covariance(ros.orientation_covariance, gz.orientation_covariance)
    fill_gz_covariance(ros.angular_velocity_covariance, gz.angular_velocity_covariance)
    fill_gz_covariance(ros.linear_acceleration_covariance, gz.linear_acceleration_covariance)
    return gz


def imu_to_ros(gz: Any) -> Any:
    ros = Imu()
    _fill_ros_imu_motion(gz, ros)
    ros.orientation_covariance = covariance_to_ros(gz.orientation_covariance, IMU_COVARIANCE_SIZE)
    ros.angular_velocity_covariance = covariance_to_ros(
        gz.angular_velocity_covariance, IMU_COVARIANCE_SIZE
    )
    ros.linear_acceleration_covariance = covariance_to_ros(
        gz.linear_acceleration_covariance, IMU_COVARIANCE_SIZE
    )
    return ros


def imu_to_gz_fortress(ros: Any) -> Any:
    """Fortress layout: the ROS covariances have nowhere to go."""
    gz = GzImuFortress()
    _fill_gz_imu_motion(ros, gz)
    return gz


def imu_to_ros_fortress(gz: Any) -> Any:
    """Fortress layout: the ROS covariances stay zero, as for a missing covariance."""
    ros = Imu()
    _fill_ros_imu_motion(gz, ros)
    return ros


def joint_state_to_gz(ros: Any) -> Any:
    gz = GzModel()
    fill_gz_header(ros.header, gz.header)
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
    ros = JointState()
    fill_ros_header(gz.header, ros.header)
    joints = gz.joint
    ros.name = [joint.name for joint in joints]
    ros.position = array("d", [joint.axis1.position for joint in joints])
    ros.velocity = array("d", [joint.axis1.velocity for joint in joints])
    ros.effort = array("d", [joint.axis1.force for joint in joints])
    return ros


def joy_to_gz(ros: Any) -> Any:
    gz = GzJoy()
    fill_gz_header(ros.header, gz.header)
    gz.axes.extend(ros.axes)
    gz.buttons.extend(ros.buttons)
    return gz


def joy_to_ros(gz: Any) -> Any:
    ros = Joy()
    fill_ros_header(gz.header, ros.header)
    ros.axes = array("f", gz.axes)
    ros.buttons = array("i", gz.buttons)
    return ros


def magnetic_field_to_gz(ros: Any) -> Any:
    """magnetic_field_covariance has no gz counterpart and is dropped."""
    gz = GzMagnetometer()
    fill_gz_header(ros.header, gz.header)
    fill_gz_vector3(ros.magnetic_field, gz.field_tesla)
    return gz


def magnetic_field_to_ros(gz: Any) -> Any:
    ros = MagneticField()
    fill_ros_header(gz.header, ros.header)
    fill_ros_vector3(gz.field_tesla, ros.magnetic_field)
    return ros


def nav_sat_fix_to_gz(ros: Any) -> Any:
    """status and covariance are dropped; the velocities are 0."""
    gz = GzNavSat()
    fill_gz_header(ros.header, gz.header)
    gz.latitude_deg = ros.latitude
    gz.longitude_deg = ros.longitude
    gz.altitude = ros.altitude
    gz.frame_id = ros.header.frame_id
    return gz


def nav_sat_fix_to_ros(gz: Any) -> Any:
    """status is STATUS_FIX, covariance unknown; frame_id always comes from gz ``frame_id``."""
    ros = NavSatFix()
    fill_ros_header(gz.header, ros.header)
    ros.header.frame_id = gz_to_ros_frame(gz.frame_id)
    ros.latitude = gz.latitude_deg
    ros.longitude = gz.longitude_deg
    ros.altitude = gz.altitude
    ros.position_covariance_type = NavSatFix.COVARIANCE_TYPE_UNKNOWN
    ros.status.status = NavSatStatus.STATUS_FIX
    return ros


def _pair(
    ros_class: type[Any],
    gz_type: str,
    to_gz: Any,
    to_ros: Any,
    bulk: BulkPath | None = None,
    *,
    default_for_gz_type: bool = False,
) -> Pair:
    name = f"sensor_msgs/msg/{ros_class.__name__}"
    return Pair(
        name, gz_type, to_gz, to_ros, ros_class, bulk=bulk, default_for_gz_type=default_for_gz_type
    )


PAIRS = (
    _pair(BatteryState, "gz.msgs.BatteryState", battery_state_to_gz, battery_state_to_ros),
    _pair(CameraInfo, "gz.msgs.CameraInfo", camera_info_to_gz, camera_info_to_ros),
    _pair(FluidPressure, "gz.msgs.FluidPressure", fluid_pressure_to_gz, fluid_pressure_to_ros),
    _pair(Image, "gz.msgs.Image", image_to_gz, image_to_ros, IMAGE_BULK),
    _pair(Imu, "gz.msgs.IMU", imu_to_gz, imu_to_ros),
    _pair(Imu, "ignition.msgs.IMU", imu_to_gz_fortress, imu_to_ros_fortress),
    _pair(JointState, "gz.msgs.Model", joint_state_to_gz, joint_state_to_ros),
    _pair(Joy, "gz.msgs.Joy", joy_to_gz, joy_to_ros),
    _pair(LaserScan, "gz.msgs.LaserScan", laser_scan_to_gz, laser_scan_to_ros),
    _pair(MagneticField, "gz.msgs.Magnetometer", magnetic_field_to_gz, magnetic_field_to_ros),
    # gps_msgs/msg/GPSFix pairs with gz.msgs.NavSat too.
    _pair(
        NavSatFix,
        "gz.msgs.NavSat",
        nav_sat_fix_to_gz,
        nav_sat_fix_to_ros,
        default_for_gz_type=True,
    ),
    _pair(
        NavSatFix,
        "gz.msgs.NavSatWithCovariance",
        nav_sat_fix_to_gz_nav_sat_with_covariance,
        nav_sat_fix_from_gz_nav_sat_with_covariance,
    ),
    _pair(
        PointCloud2,
        "gz.msgs.PointCloudPacked",
        point_cloud2_to_gz,
        point_cloud2_to_ros,
        POINT_CLOUD2_BULK,
    ),
    _pair(Range, "gz.msgs.LaserScan", range_to_gz, range_to_ros),
)
