"""sensor_msgs/msg/NavSatFix <-> gz.msgs.NavSatWithCovariance (Jetty, gz-msgs 12).

ros_gz_bridge has no such pair; this one extends its NavSat conversion
(docs/conversions-per-package.md §3.5, ``sensor_msgs.py``) with the position covariance that
NavSatFix can carry:

- Position, header and frame_id as for ``gz.msgs.NavSat``: G→R takes ``header.frame_id`` from
  gz ``frame_id`` (``::`` -> ``/``) and sets ``status.status`` to STATUS_FIX; R→G sends the ROS
  frame_id in both places and zero velocities; ``status`` is not sent.
- ``position_covariance`` <-> gz ``position_covariance`` (row-major 3x3, ENU on both sides;
  float32 on the wire, so R→G rounds) and ``position_covariance_type`` <-> the gz field of
  the same name (same numbering). R→G always sends all 9 values.
- G→R with no covariance values gives the all-zero covariance and COVARIANCE_TYPE_UNKNOWN,
  whatever type the gz message names: NavSatFix has no other way to say "not known".
- The velocities, their covariance and its type have no NavSatFix field and are dropped.
- A covariance of neither 0 nor 9 values, or a covariance type outside 0..3, raises
  ConversionError naming the field; the plain NavSat pair has no such fields to check.

Not in Fortress or Harmonic: a simulator older than Jetty never sends this type.
"""

from __future__ import annotations

from typing import Any

from sensor_msgs.msg import NavSatFix, NavSatStatus

from ros_gz_bridge_py.converters._fields import Value, fields, same
from ros_gz_bridge_py.converters.covariance import fill_gz_covariance
from ros_gz_bridge_py.converters.std_msgs import HEADER, gz_to_ros_frame
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

_GzNavSatWithCovariance = message_class("gz.msgs.NavSatWithCovariance")

COVARIANCE_SIZE = 9
#: COVARIANCE_TYPE_UNKNOWN .. COVARIANCE_TYPE_KNOWN, numbered alike on both sides.
_COVARIANCE_TYPES = range(4)

#: What every gz NavSat pair (NavSatFix, GPSFix; NavSat, NavSatWithCovariance) carries alike:
#: header and position; R→G sends the ROS frame_id in both places, G→R takes it from gz
#: ``frame_id`` (``::`` -> ``/``), whatever the header says.
NAV_SAT_POSITION = fields(
    ("header", HEADER),
    ("header.frame_id", "frame_id", Value(same, gz_to_ros_frame)),
    ("latitude", "latitude_deg"),
    ("longitude", "longitude_deg"),
    "altitude",
)


def new_nav_sat_fix() -> Any:
    """A NavSatFix with what no gz NavSat says: STATUS_FIX, and an unknown covariance."""
    return NavSatFix(
        status=NavSatStatus(status=NavSatStatus.STATUS_FIX),
        position_covariance_type=NavSatFix.COVARIANCE_TYPE_UNKNOWN,
    )


def _checked_type(value: int, where: str) -> int:
    if value not in _COVARIANCE_TYPES:
        msg = f"{where} position_covariance_type is {value}; COVARIANCE_TYPE_* are 0..3"
        raise ConversionError(msg)
    return value


def nav_sat_fix_to_gz_nav_sat_with_covariance(ros: Any) -> Any:
    gz = _GzNavSatWithCovariance()
    NAV_SAT_POSITION.to_gz(ros, gz)
    fill_gz_covariance(ros.position_covariance, gz.position_covariance)
    gz.position_covariance_type = _checked_type(ros.position_covariance_type, "NavSatFix")
    return gz


def nav_sat_fix_from_gz_nav_sat_with_covariance(gz: Any) -> Any:
    covariance = list(gz.position_covariance.data)
    kind = _checked_type(gz.position_covariance_type, "NavSatWithCovariance")
    if len(covariance) not in (0, COVARIANCE_SIZE):
        msg = (
            f"NavSatWithCovariance position_covariance has {len(covariance)} values; "
            f"NavSatFix takes {COVARIANCE_SIZE} (or none)"
        )
        raise ConversionError(msg)
    ros = new_nav_sat_fix()
    NAV_SAT_POSITION.to_ros(gz, ros)
    if covariance:
        ros.position_covariance = covariance
        ros.position_covariance_type = kind
    return ros
