"""marine_acoustic_msgs/msg/Dvl <-> gz.msgs.DVLVelocityTracking (ros_gz PR #789, Jazzy 1.0.22).

The two messages model a DVL differently, so the mapping is lossy both ways. It follows the
reference converter as merged (the revision that leaves per-beam covariances empty):

R→G
- header; ``type`` PISTON / PHASED_ARRAY from ``dvl_type`` (anything else UNSPECIFIED);
  ``target.type`` BOTTOM / WATER_MASS from ``velocity_mode`` (anything else UNSPECIFIED), and
  ``target.range.mean`` = ``altitude`` when ``altitude >= 0``.
- ``velocity``: reference SHIP, mean = ``velocity``, covariance = the 9 ``velocity_covar``.
- One locked beam per good beam ``i < num_good_beams``: id ``i + 1``, velocity reference SHIP
  with mean ``beam_unit_vec[i] * beam_velocity[i]`` and no covariance, range mean/variance
  from ``range[i]``/``range_covar[i]``, rssi from ``beam_quality[i]``. ``status`` stays 0.
G→R
- header; ``velocity_mode`` WATER for a WATER_MASS target, else BOTTOM; ``dvl_type``
  PHASED_ARRAY or else PISTON; ``velocity`` = velocity mean; ``velocity_covar[i]`` = the
  i-th covariance value, -1 where there is none.
- ``altitude`` = target range mean for a BOTTOM target whose range is present and positive,
  else -1; ``course_gnd = atan2(vy, vx)``, ``speed_gnd = sqrt(vx² + vy²)``; ``sound_speed`` -1.
- The locked beams among the first four, packed from index 0: ``beam_unit_vec`` = the beam
  velocity direction (0 for a zero velocity), ``beam_velocity`` its length, ``range``/
  ``range_covar`` the range mean/variance, ``beam_quality`` the rssi, ``beam_velocity_covar``
  -1; ``num_good_beams`` their count, both ``*_valid`` flags true when there is one.

Differences from ros_gz_bridge:
- R→G with ``num_good_beams`` above 4 raises ConversionError naming the field; the reference
  reads past the ends of the four-element beam arrays (undefined behaviour).
- G→R float32 fields (range_covar, beam_quality, beam_velocity) take values beyond the float32
  range as ±inf, as the reference's implicit narrowing does on IEEE hardware.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from geometry_msgs.msg import Vector3
from marine_acoustic_msgs.msg import Dvl

from ros_gz_bridge_py.converters.geometry_msgs import VECTOR3
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

_GzDvl = message_class("gz.msgs.DVLVelocityTracking")
_GzTarget = message_class("gz.msgs.DVLTrackingTarget")
_GzEstimate = message_class("gz.msgs.DVLKinematicEstimate")

#: Beams a ROS Dvl has room for.
BEAMS = 4
#: Entries of a 3x3 covariance.
COVARIANCE_SIZE = 9
#: What the ROS message uses for "not known".
UNKNOWN = -1.0

_GZ_TYPE = {
    Dvl.DVL_TYPE_PISTON: _GzDvl.DVL_TYPE_PISTON,
    Dvl.DVL_TYPE_PHASED_ARRAY: _GzDvl.DVL_TYPE_PHASED_ARRAY,
}
_GZ_TARGET = {
    Dvl.DVL_MODE_BOTTOM: _GzTarget.DVL_TARGET_BOTTOM,
    Dvl.DVL_MODE_WATER: _GzTarget.DVL_TARGET_WATER_MASS,
}


def _fill_gz_beam(ros: Any, index: int, beam: Any) -> None:
    beam.id = index + 1
    beam.velocity.reference = _GzEstimate.DVL_REFERENCE_SHIP
    unit, speed = ros.beam_unit_vec[index], float(ros.beam_velocity[index])
    beam.velocity.mean.x = unit.x * speed
    beam.velocity.mean.y = unit.y * speed
    beam.velocity.mean.z = unit.z * speed
    beam.range.mean = float(ros.range[index])
    beam.range.variance = float(ros.range_covar[index])
    beam.rssi = float(ros.beam_quality[index])
    beam.locked = True


def dvl_to_gz(ros: Any) -> Any:
    count = ros.num_good_beams
    if count > BEAMS:
        msg = f"Dvl num_good_beams is {count}; the message holds at most {BEAMS} beams"
        raise ConversionError(msg)
    gz = _GzDvl()
    HEADER.to_gz(ros.header, gz.header)
    gz.type = _GZ_TYPE.get(ros.dvl_type, _GzDvl.DVL_TYPE_UNSPECIFIED)
    for index in range(count):
        _fill_gz_beam(ros, index, gz.beams.add())
    gz.velocity.reference = _GzEstimate.DVL_REFERENCE_SHIP
    VECTOR3.to_gz(ros.velocity, gz.velocity.mean)
    gz.velocity.covariance.extend(float(value) for value in ros.velocity_covar)
    gz.target.type = _GZ_TARGET.get(ros.velocity_mode, _GzTarget.DVL_TARGET_UNSPECIFIED)
    if ros.altitude >= 0:
        gz.target.range.mean = ros.altitude
    return gz


def _altitude(target: Any) -> float:
    """The bottom range, where the gz message has one; else the ROS "unknown"."""
    if target.type != _GzTarget.DVL_TARGET_BOTTOM or not target.HasField("range"):
        return UNKNOWN
    mean = float(target.range.mean)
    return mean if mean > 0 else UNKNOWN


def _float32s(values: list[float]) -> Any:
    """Four float32 values, narrowed like a C++ double-to-float assignment."""
    with np.errstate(over="ignore"):
        return np.array(values + [0.0] * (BEAMS - len(values)), dtype=np.float32)


def _fill_ros_beams(gz_beams: Any, ros: Any) -> None:
    locked = [beam for beam in gz_beams[:BEAMS] if beam.locked]
    units, speeds = [], []
    for beam in locked:
        mean = beam.velocity.mean
        speed = math.sqrt(mean.x * mean.x + mean.y * mean.y + mean.z * mean.z)
        if speed > 0:
            units.append(Vector3(x=mean.x / speed, y=mean.y / speed, z=mean.z / speed))
        else:
            units.append(Vector3())
        speeds.append(speed)
    ros.beam_unit_vec = units + [Vector3() for _ in range(BEAMS - len(units))]
    ros.range = [beam.range.mean for beam in locked] + [0.0] * (BEAMS - len(locked))
    ros.range_covar = _float32s([beam.range.variance for beam in locked])
    ros.beam_quality = _float32s([beam.rssi for beam in locked])
    ros.beam_velocity = _float32s(speeds)
    ros.beam_velocity_covar = _float32s([UNKNOWN] * len(locked))
    ros.num_good_beams = len(locked)
    ros.beam_ranges_valid = ros.beam_velocities_valid = bool(locked)


def dvl_to_ros(gz: Any) -> Any:
    ros = Dvl()
    HEADER.to_ros(gz.header, ros.header)
    water = gz.target.type == _GzTarget.DVL_TARGET_WATER_MASS
    ros.velocity_mode = Dvl.DVL_MODE_WATER if water else Dvl.DVL_MODE_BOTTOM
    phased = gz.type == _GzDvl.DVL_TYPE_PHASED_ARRAY
    ros.dvl_type = Dvl.DVL_TYPE_PHASED_ARRAY if phased else Dvl.DVL_TYPE_PISTON
    VECTOR3.to_ros(gz.velocity.mean, ros.velocity)
    covariance = list(gz.velocity.covariance[:COVARIANCE_SIZE])
    ros.velocity_covar = covariance + [UNKNOWN] * (COVARIANCE_SIZE - len(covariance))
    ros.altitude = _altitude(gz.target)
    vx, vy = ros.velocity.x, ros.velocity.y
    ros.course_gnd = math.atan2(vy, vx)
    ros.speed_gnd = math.sqrt(vx * vx + vy * vy)
    ros.sound_speed = UNKNOWN
    _fill_ros_beams(gz.beams, ros)
    return ros


PAIRS = (Pair.of(Dvl, "gz.msgs.DVLVelocityTracking", dvl_to_gz, dvl_to_ros),)
