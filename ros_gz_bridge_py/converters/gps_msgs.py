"""gps_msgs/msg/GPSFix <-> gz.msgs.NavSat (docs/conversions-per-package.md §3.6).

``track`` is read and written as radians counter-clockwise from East, as the reference does,
although the ``.msg`` documents degrees from North. Only position, speed, track and climb
survive; G→R reports ``status.status = STATUS_GBAS_FIX`` and an unknown covariance.
"""

from __future__ import annotations

import math
from typing import Any

from gps_msgs.msg import GPSFix, GPSStatus

from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.sensor_msgs_navsat import NAV_SAT_POSITION
from ros_gz_bridge_py.msgs import message_class

_GzNavSat = message_class("gz.msgs.NavSat")


def gps_fix_to_gz(ros: Any) -> Any:
    gz = _GzNavSat()
    NAV_SAT_POSITION.to_gz(ros, gz)
    gz.velocity_east = math.cos(ros.track) * ros.speed
    gz.velocity_north = math.sin(ros.track) * ros.speed
    gz.velocity_up = ros.climb
    return gz


def gps_fix_to_ros(gz: Any) -> Any:
    ros = GPSFix()
    NAV_SAT_POSITION.to_ros(gz, ros)
    ve, vn = gz.velocity_east, gz.velocity_north
    ros.speed = math.sqrt(ve * ve + vn * vn)
    ros.track = math.atan2(vn, ve)
    ros.climb = gz.velocity_up
    ros.position_covariance_type = GPSFix.COVARIANCE_TYPE_UNKNOWN
    ros.status.status = GPSStatus.STATUS_GBAS_FIX
    return ros


PAIRS = (Pair.of(GPSFix, "gz.msgs.NavSat", gps_fix_to_gz, gps_fix_to_ros),)
