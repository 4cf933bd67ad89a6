"""sensor_msgs/NavSatFix <-> gz.msgs.NavSatWithCovariance (Jetty; no C++ counterpart)."""

from __future__ import annotations

from typing import Any

import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import NavSatFix, NavSatStatus

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.converters import sensor_msgs_navsat as conv
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros import light_reader

GzNavSatWithCovariance = message_class("gz.msgs.NavSatWithCovariance")

#: Nine distinct values that float32 holds exactly, so both directions compare exactly.
COVARIANCE = [0.25, 0.5, 0.75, 1.5, 2.25, 3.125, -0.0625, 4.5, 9.75]


def ros_fix() -> Any:
    ros = NavSatFix(latitude=47.397742, longitude=8.545594, altitude=488.25)
    ros.header.frame_id = "gps_link"
    ros.header.stamp.sec, ros.header.stamp.nanosec = 81, 82
    ros.status.status = NavSatStatus.STATUS_GBAS_FIX
    ros.status.service = NavSatStatus.SERVICE_GALILEO
    ros.position_covariance = COVARIANCE
    ros.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    return ros


def gz_fix(covariance: list[float], kind: int) -> Any:
    gz = GzNavSatWithCovariance(
        latitude_deg=-33.8688,
        longitude_deg=151.2093,
        altitude=58.25,
        position_covariance_type=kind,
        velocity_east=3.0,
        velocity_north=4.0,
        velocity_up=-0.5,
        velocity_covariance_type=NavSatFix.COVARIANCE_TYPE_KNOWN,
        frame_id="rover::gps",
    )
    gz.header.stamp.sec, gz.header.stamp.nsec = 91, 92
    gz.header.data.add(key="frame_id", value=["overwritten"])
    gz.position_covariance.data.extend(covariance)
    gz.velocity_covariance.data.extend([7.0] * 9)
    return gz


def test_pair_is_registered_beside_the_navsat_default() -> None:
    registry = default_registry()
    assert registry.gz_types_for("sensor_msgs/msg/NavSatFix") == [
        "gz.msgs.NavSat",
        "gz.msgs.NavSatWithCovariance",
    ]
    pair = registry.get("sensor_msgs/msg/NavSatFix", "gz.msgs.NavSatWithCovariance")
    assert pair.to_gz is conv.nav_sat_fix_to_gz_nav_sat_with_covariance
    assert pair.to_ros is conv.nav_sat_fix_from_gz_nav_sat_with_covariance


def test_to_gz_carries_position_and_its_covariance() -> None:
    gz = conv.nav_sat_fix_to_gz_nav_sat_with_covariance(ros_fix())
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (81, 82)
    assert [(e.key, list(e.value)) for e in gz.header.data] == [("frame_id", ["gps_link"])]
    assert gz.frame_id == "gps_link"
    assert (gz.latitude_deg, gz.longitude_deg, gz.altitude) == (47.397742, 8.545594, 488.25)
    assert list(gz.position_covariance.data) == COVARIANCE
    assert gz.position_covariance_type == NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    assert (gz.velocity_east, gz.velocity_north, gz.velocity_up) == (0.0, 0.0, 0.0)
    assert not gz.HasField("velocity_covariance")
    assert gz.velocity_covariance_type == NavSatFix.COVARIANCE_TYPE_UNKNOWN


def test_to_gz_rounds_the_covariance_to_float32() -> None:
    ros = ros_fix()
    ros.position_covariance = [0.1] * 9
    gz = conv.nav_sat_fix_to_gz_nav_sat_with_covariance(ros)
    assert gz.position_covariance.data[0] == pytest.approx(0.1, rel=1e-7)
    assert gz.position_covariance.data[0] != 0.1


def test_default_fix_sends_nine_zeros_of_unknown_type() -> None:
    gz = conv.nav_sat_fix_to_gz_nav_sat_with_covariance(NavSatFix())
    assert list(gz.position_covariance.data) == [0.0] * 9
    assert gz.position_covariance_type == NavSatFix.COVARIANCE_TYPE_UNKNOWN
    assert gz.HasField("header")


def test_light_tree_of_a_valid_fix_converts_like_the_rclpy_message() -> None:
    # tests/unit/ros/test_light_reader.py fills an invalid covariance type: only the error path.
    msg = ros_fix()
    tree = light_reader.read(serialize_message(msg), NavSatFix)
    assert tree is not None
    expected = conv.nav_sat_fix_to_gz_nav_sat_with_covariance(msg)
    assert conv.nav_sat_fix_to_gz_nav_sat_with_covariance(tree) == expected


def test_to_ros_carries_position_and_its_covariance() -> None:
    gz = gz_fix(COVARIANCE, NavSatFix.COVARIANCE_TYPE_APPROXIMATED)
    ros = conv.nav_sat_fix_from_gz_nav_sat_with_covariance(gz)
    assert isinstance(ros, NavSatFix)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (91, 92)
    # As for gz.msgs.NavSat: frame_id always comes from gz `frame_id`, `::` -> `/`.
    assert ros.header.frame_id == "rover/gps"
    assert (ros.latitude, ros.longitude, ros.altitude) == (-33.8688, 151.2093, 58.25)
    assert list(ros.position_covariance) == COVARIANCE
    assert ros.position_covariance_type == NavSatFix.COVARIANCE_TYPE_APPROXIMATED
    assert ros.status.status == NavSatStatus.STATUS_FIX
    assert ros.status.service == 0


@pytest.mark.parametrize("kind", range(4))
def test_every_covariance_type_keeps_its_number(kind: int) -> None:
    ros = ros_fix()
    ros.position_covariance_type = kind
    gz = conv.nav_sat_fix_to_gz_nav_sat_with_covariance(ros)
    assert gz.position_covariance_type == kind
    assert conv.nav_sat_fix_from_gz_nav_sat_with_covariance(gz).position_covariance_type == kind


def test_no_covariance_values_read_as_unknown_whatever_the_type() -> None:
    gz = gz_fix([], NavSatFix.COVARIANCE_TYPE_KNOWN)
    ros = conv.nav_sat_fix_from_gz_nav_sat_with_covariance(gz)
    assert list(ros.position_covariance) == [0.0] * 9
    assert ros.position_covariance_type == NavSatFix.COVARIANCE_TYPE_UNKNOWN
    assert ros.latitude == -33.8688


def test_round_trip_keeps_everything_navsatfix_and_gz_share() -> None:
    ros = ros_fix()
    back = conv.nav_sat_fix_from_gz_nav_sat_with_covariance(
        conv.nav_sat_fix_to_gz_nav_sat_with_covariance(ros)
    )
    # status is not on the wire; the reader reports STATUS_FIX.
    ros.status = NavSatStatus(status=NavSatStatus.STATUS_FIX)
    assert back == ros


@pytest.mark.parametrize("size", [1, 8, 10, 36])
def test_a_covariance_of_another_size_is_an_error(size: int) -> None:
    gz = gz_fix([1.0] * size, NavSatFix.COVARIANCE_TYPE_KNOWN)
    with pytest.raises(ConversionError, match=rf"position_covariance has {size} values"):
        conv.nav_sat_fix_from_gz_nav_sat_with_covariance(gz)


def test_an_unknown_covariance_type_is_an_error_both_ways() -> None:
    with pytest.raises(ConversionError, match="position_covariance_type is 4"):
        conv.nav_sat_fix_from_gz_nav_sat_with_covariance(gz_fix(COVARIANCE, 4))
    ros = ros_fix()
    ros.position_covariance_type = 200
    with pytest.raises(ConversionError, match="position_covariance_type is 200"):
        conv.nav_sat_fix_to_gz_nav_sat_with_covariance(ros)
