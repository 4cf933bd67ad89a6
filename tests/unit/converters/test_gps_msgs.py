"""gps_msgs/msg/GPSFix <-> gz.msgs.NavSat (docs/conversions-per-package.md §3.6)."""

from __future__ import annotations

import math

from gps_msgs.msg import GPSFix, GPSStatus

from ros_gz_bridge_py.converters.gps_msgs import gps_fix_to_gz, gps_fix_to_ros
from ros_gz_bridge_py.msgs import message_class

GzNavSat = message_class("gz.msgs.NavSat")


def test_gps_fix_to_gz_uses_track_as_radians_from_east() -> None:
    ros = GPSFix(latitude=48.125, longitude=-11.5, altitude=512.25, speed=2.0, climb=-0.75)
    ros.track = math.pi / 6
    ros.header.stamp.sec = 2
    ros.header.stamp.nanosec = 3
    ros.header.frame_id = "gps::link"
    ros.pitch = 9.0
    ros.err = 4.0
    ros.position_covariance = [1.0] * 9
    ros.status.status = GPSStatus.STATUS_DGPS_FIX
    gz = gps_fix_to_gz(ros)
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (2, 3)
    assert [(d.key, list(d.value)) for d in gz.header.data] == [("frame_id", ["gps::link"])]
    assert (gz.latitude_deg, gz.longitude_deg, gz.altitude) == (48.125, -11.5, 512.25)
    assert gz.frame_id == "gps::link"
    assert gz.velocity_east == math.cos(math.pi / 6) * 2.0
    assert gz.velocity_north == math.sin(math.pi / 6) * 2.0
    assert gz.velocity_up == -0.75


def test_gps_fix_to_ros_derives_speed_track_and_status() -> None:
    gz = GzNavSat(
        latitude_deg=-33.5,
        longitude_deg=151.25,
        altitude=-4.5,
        velocity_east=3.0,
        velocity_north=-4.0,
        velocity_up=1.25,
        frame_id="model::gps",
    )
    gz.header.stamp.sec = 7
    gz.header.data.add(key="frame_id", value=["ignored"])
    ros = gps_fix_to_ros(gz)
    assert (ros.header.stamp.sec, ros.header.frame_id) == (7, "model/gps")
    assert (ros.latitude, ros.longitude, ros.altitude) == (-33.5, 151.25, -4.5)
    assert ros.speed == 5.0
    assert ros.track == math.atan2(-4.0, 3.0)
    assert ros.climb == 1.25
    assert ros.status.status == GPSStatus.STATUS_GBAS_FIX
    assert ros.status.satellites_used == 0
    assert ros.position_covariance_type == GPSFix.COVARIANCE_TYPE_UNKNOWN
    assert list(ros.position_covariance) == [0.0] * 9
    assert (ros.pitch, ros.err, ros.hdop, ros.time) == (0.0, 0.0, 0.0, 0.0)


def test_empty_gz_frame_id_overwrites_the_header_frame() -> None:
    gz = GzNavSat()
    gz.header.data.add(key="frame_id", value=["from_header"])
    assert gps_fix_to_ros(gz).header.frame_id == ""


def test_velocity_round_trip_within_rounding() -> None:
    ros = GPSFix(speed=3.5, track=-2.0, climb=0.5)
    back = gps_fix_to_ros(gps_fix_to_gz(ros))
    assert math.isclose(back.speed, 3.5, rel_tol=1e-12)
    assert math.isclose(back.track, -2.0, rel_tol=1e-12)
    assert back.climb == 0.5
