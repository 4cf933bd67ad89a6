"""sensor_msgs pairs except Image/CameraInfo and LaserScan/Range/PointCloud2.

The rules: docs/conversions-per-package.md §3.5.
"""

from __future__ import annotations

import math
from typing import Any

from sensor_msgs.msg import (
    BatteryState,
    FluidPressure,
    Imu,
    JointState,
    Joy,
    MagneticField,
    NavSatFix,
    NavSatStatus,
)

from ros_gz_bridge_py.converters import sensor_msgs as conv
from ros_gz_bridge_py.msgs import message_class

GzImuHarmonic = message_class("gz.msgs.IMU")
GzImuFortress = message_class("ignition.msgs.IMU")


def stamped(msg: Any, frame: str = "sensor") -> Any:
    msg.header.frame_id = frame
    msg.header.stamp.sec, msg.header.stamp.nanosec = 7, 8
    return msg


def test_pairs_are_listed_in_index_order_with_laser_scan_before_range() -> None:
    names = [(p.ros_type.rsplit("/", 1)[1], p.gz_type) for p in conv.PAIRS]
    assert names.index(("LaserScan", "gz.msgs.LaserScan")) < names.index(
        ("Range", "gz.msgs.LaserScan")
    )
    assert ("Imu", "gz.msgs.IMU") in names
    assert ("Imu", "ignition.msgs.IMU") in names
    assert ("NavSatFix", "gz.msgs.NavSatWithCovariance") in names
    # NavSat stays the default gz type of NavSatFix.
    assert names.index(("NavSatFix", "gz.msgs.NavSat")) < names.index(
        ("NavSatFix", "gz.msgs.NavSatWithCovariance")
    )
    assert len(names) == 14


def sample_imu() -> Any:
    ros = stamped(Imu(), "imu_link")
    ros.orientation.x, ros.orientation.y, ros.orientation.z, ros.orientation.w = 0.1, 0.2, 0.3, 0.4
    ros.angular_velocity.x, ros.angular_velocity.y, ros.angular_velocity.z = 1.5, -2.25, 3.125
    ros.linear_acceleration.x, ros.linear_acceleration.z = 9.5, -9.75
    ros.orientation_covariance = [float(i) for i in range(1, 10)]
    ros.angular_velocity_covariance = [float(i) for i in range(11, 20)]
    ros.linear_acceleration_covariance = [float(i) for i in range(21, 30)]
    return ros


def test_imu_harmonic_round_trips_with_covariances_and_entity_name() -> None:
    gz = conv.imu_to_gz(sample_imu())
    assert gz.entity_name == "imu_link"
    assert list(gz.angular_velocity_covariance.data) == [float(i) for i in range(11, 20)]
    assert conv.imu_to_ros(gz) == sample_imu()


def test_imu_harmonic_default_covariances_are_present() -> None:
    gz = conv.imu_to_gz(Imu())
    for name in ("orientation_covariance", "angular_velocity_covariance"):
        assert gz.HasField(name)
    assert gz.HasField("linear_acceleration_covariance")


def test_imu_fortress_decodes_without_swapping_angular_velocity_into_covariance() -> None:
    wire = conv.imu_to_gz_fortress(sample_imu()).SerializeToString()
    fortress = GzImuFortress.FromString(wire)
    ros = conv.imu_to_ros_fortress(fortress)
    assert (ros.angular_velocity.x, ros.angular_velocity.y, ros.angular_velocity.z) == (
        1.5,
        -2.25,
        3.125,
    )
    assert (ros.linear_acceleration.x, ros.linear_acceleration.z) == (9.5, -9.75)
    assert list(ros.orientation_covariance) == [0.0] * 9
    assert list(ros.angular_velocity_covariance) == [0.0] * 9
    # The same bytes read with the Harmonic layout put angular velocity in field 5's place.
    misread = conv.imu_to_ros(GzImuHarmonic.FromString(wire))
    assert misread.angular_velocity.x == 9.5  # Fortress field 5 is linear_acceleration
    assert misread.linear_acceleration.x == 0.0


def test_imu_fortress_lookup_is_exact() -> None:
    by_gz = {p.gz_type: p for p in conv.PAIRS if p.ros_type == "sensor_msgs/msg/Imu"}
    assert by_gz["ignition.msgs.IMU"].to_gz is conv.imu_to_gz_fortress
    assert conv.imu_to_gz_fortress(Imu()).DESCRIPTOR.full_name == "ignition.msgs.IMU"


def test_imu_covariance_of_wrong_size_reads_as_zeros() -> None:
    gz = GzImuHarmonic()
    gz.orientation_covariance.data.extend([1.0] * 8)
    assert list(conv.imu_to_ros(gz).orientation_covariance) == [0.0] * 9


def test_battery_state() -> None:
    ros = stamped(BatteryState(voltage=12.5, current=-1.25, charge=3.0, capacity=4.0))
    ros.percentage = 0.75
    ros.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_FULL
    ros.temperature = 30.0
    gz = conv.battery_state_to_gz(ros)
    assert (gz.voltage, gz.current, gz.percentage, gz.power_supply_status) == (12.5, -1.25, 0.75, 4)
    back = conv.battery_state_to_ros(gz)
    assert (back.voltage, back.charge, back.capacity, back.power_supply_status) == (
        12.5,
        3.0,
        4.0,
        4,
    )
    assert math.isnan(back.design_capacity)
    assert back.present
    assert back.temperature == 0.0
    ros.power_supply_status = 200
    assert conv.battery_state_to_gz(ros).power_supply_status == 0


def test_fluid_pressure_round_trips() -> None:
    ros = stamped(FluidPressure(fluid_pressure=101325.5, variance=0.25))
    assert conv.fluid_pressure_to_ros(conv.fluid_pressure_to_gz(ros)) == ros


def test_joint_state_to_model_and_back() -> None:
    ros = stamped(JointState(name=["a", "b"], position=[1.5, -2.5], velocity=[0.5, 0.25]))
    ros.effort = [3.0, 4.0]
    gz = conv.joint_state_to_gz(ros)
    assert [(j.name, j.axis1.position, j.axis1.velocity, j.axis1.force) for j in gz.joint] == [
        ("a", 1.5, 0.5, 3.0),
        ("b", -2.5, 0.25, 4.0),
    ]
    assert conv.joint_state_to_ros(gz) == ros


def test_joint_state_with_short_lists_uses_defaults() -> None:
    gz = conv.joint_state_to_gz(JointState(name=["only"], position=[1.0, 2.0]))
    assert [(j.name, j.axis1.velocity, j.axis1.force) for j in gz.joint] == [
        ("only", 0.0, 0.0),
        ("", 0.0, 0.0),
    ]


def test_joy_round_trips() -> None:
    ros = stamped(Joy(axes=[0.5, -1.0], buttons=[1, 0, -3]))
    assert conv.joy_to_ros(conv.joy_to_gz(ros)) == ros


def test_magnetic_field_drops_covariance() -> None:
    ros = stamped(MagneticField())
    ros.magnetic_field.x, ros.magnetic_field.z = 1e-5, -2e-5
    ros.magnetic_field_covariance = [1.0] * 9
    gz = conv.magnetic_field_to_gz(ros)
    assert gz.HasField("field_tesla")
    back = conv.magnetic_field_to_ros(gz)
    assert (back.magnetic_field.x, back.magnetic_field.z) == (1e-5, -2e-5)
    assert list(back.magnetic_field_covariance) == [0.0] * 9


def test_nav_sat_fix() -> None:
    ros = stamped(NavSatFix(latitude=47.5, longitude=-8.25, altitude=400.125), "gps::link")
    ros.status.status = NavSatStatus.STATUS_GBAS_FIX
    ros.position_covariance_type = NavSatFix.COVARIANCE_TYPE_KNOWN
    gz = conv.nav_sat_fix_to_gz(ros)
    assert (gz.latitude_deg, gz.longitude_deg, gz.altitude) == (47.5, -8.25, 400.125)
    assert gz.frame_id == "gps::link"
    assert (gz.velocity_east, gz.velocity_north, gz.velocity_up) == (0.0, 0.0, 0.0)
    back = conv.nav_sat_fix_to_ros(gz)
    assert back.header.frame_id == "gps/link"
    assert back.status.status == NavSatStatus.STATUS_FIX
    assert back.position_covariance_type == NavSatFix.COVARIANCE_TYPE_UNKNOWN
    assert (back.latitude, back.altitude) == (47.5, 400.125)
