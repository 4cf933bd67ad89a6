"""marine_acoustic_msgs/Dvl <-> gz.msgs.DVLVelocityTracking (ros_gz PR #789)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import Vector3
from marine_acoustic_msgs.msg import Dvl
from rclpy.serialization import serialize_message

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.converters import marine_acoustic_msgs as conv
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros import light_reader

GzDvl = message_class("gz.msgs.DVLVelocityTracking")
GzTarget = message_class("gz.msgs.DVLTrackingTarget")
GzEstimate = message_class("gz.msgs.DVLKinematicEstimate")

COVARIANCE = [0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5]


def xyz(vector: Any) -> tuple[float, float, float]:
    return (vector.x, vector.y, vector.z)


def ros_dvl(good_beams: int = 3) -> Any:
    """A Dvl whose beams hold distinct values in every slot, the unused fourth one too."""
    ros = Dvl(
        velocity_mode=Dvl.DVL_MODE_WATER,
        dvl_type=Dvl.DVL_TYPE_PHASED_ARRAY,
        velocity=Vector3(x=0.75, y=-0.25, z=0.125),
        velocity_covar=COVARIANCE,
        altitude=12.5,
        course_gnd=9.0,
        speed_gnd=8.0,
        num_good_beams=good_beams,
        sound_speed=1500.0,
        beam_ranges_valid=True,
        beam_velocities_valid=True,
        beam_unit_vec=[
            Vector3(x=0.5, y=0.0, z=-1.0),
            Vector3(x=0.0, y=0.5, z=-2.0),
            Vector3(x=-0.5, y=0.0, z=-4.0),
            Vector3(x=0.0, y=-0.5, z=-8.0),
        ],
        range=[10.5, 20.5, 30.5, 40.5],
        range_covar=[0.125, 0.25, 0.375, 0.5],
        beam_quality=[61.0, 62.0, 63.0, 64.0],
        beam_velocity=[2.0, -3.0, 0.5, 7.0],
        beam_velocity_covar=[0.01, 0.02, 0.03, 0.04],
    )
    ros.header.frame_id = "dvl_link"
    ros.header.stamp.sec, ros.header.stamp.nanosec = 101, 102
    return ros


def gz_beam(gz: Any, mean: tuple[float, float, float], base: float, locked: bool) -> Any:
    beam = gz.beams.add(id=int(base), rssi=base + 0.5, nsd=base + 0.75, locked=locked)
    beam.velocity.mean.x, beam.velocity.mean.y, beam.velocity.mean.z = mean
    beam.velocity.covariance.extend([base] * 9)
    beam.range.mean, beam.range.variance = base + 100.0, base + 0.25
    return beam


def gz_dvl() -> Any:
    gz = GzDvl(type=GzDvl.DVL_TYPE_PHASED_ARRAY, status=77)
    gz.header.stamp.sec, gz.header.stamp.nsec = 111, 112
    gz.header.data.add(key="frame_id", value=["sub::dvl"])
    gz.target.type = GzTarget.DVL_TARGET_BOTTOM
    gz.target.range.mean, gz.target.range.variance = 23.5, 0.5
    gz.velocity.reference = GzEstimate.DVL_REFERENCE_EARTH
    gz.velocity.mean.x, gz.velocity.mean.y, gz.velocity.mean.z = 3.0, -4.0, 0.25
    gz.velocity.covariance.extend(COVARIANCE)
    gz_beam(gz, (0.0, 3.0, -4.0), 1.0, locked=True)
    gz_beam(gz, (6.0, 0.0, 8.0), 2.0, locked=False)
    gz_beam(gz, (0.0, 0.0, 0.0), 3.0, locked=True)
    gz_beam(gz, (-2.0, 0.0, 0.0), 4.0, locked=True)
    gz_beam(gz, (1.0, 1.0, 1.0), 5.0, locked=True)  # a fifth beam: no room in ROS
    return gz


def test_pair_is_registered() -> None:
    pair = default_registry().get("marine_acoustic_msgs/msg/Dvl", "gz.msgs.DVLVelocityTracking")
    assert (pair.to_gz, pair.to_ros, pair.ros_class) == (conv.dvl_to_gz, conv.dvl_to_ros, Dvl)


# --- ROS -> Gazebo --------------------------------------------------------------------------


def test_to_gz_converts_header_type_target_and_velocity() -> None:
    gz = conv.dvl_to_gz(ros_dvl())
    assert (gz.header.stamp.sec, gz.header.stamp.nsec) == (101, 102)
    assert [(e.key, list(e.value)) for e in gz.header.data] == [("frame_id", ["dvl_link"])]
    assert gz.type == GzDvl.DVL_TYPE_PHASED_ARRAY
    assert gz.target.type == GzTarget.DVL_TARGET_WATER_MASS
    assert (gz.target.range.mean, gz.target.range.variance) == (12.5, 0.0)
    assert not gz.target.HasField("position")
    assert gz.velocity.reference == GzEstimate.DVL_REFERENCE_SHIP
    assert xyz(gz.velocity.mean) == (0.75, -0.25, 0.125)
    assert list(gz.velocity.covariance) == COVARIANCE
    assert gz.status == 0


def test_to_gz_makes_one_locked_beam_per_good_beam() -> None:
    gz = conv.dvl_to_gz(ros_dvl(good_beams=3))
    assert [beam.id for beam in gz.beams] == [1, 2, 3]
    assert all(beam.locked for beam in gz.beams)
    # The beam velocity vector is the unit vector scaled by the speed along the beam.
    assert [xyz(beam.velocity.mean) for beam in gz.beams] == [
        (1.0, 0.0, -2.0),
        (0.0, -1.5, 6.0),
        (-0.25, 0.0, -2.0),
    ]
    assert {beam.velocity.reference for beam in gz.beams} == {GzEstimate.DVL_REFERENCE_SHIP}
    assert [list(beam.velocity.covariance) for beam in gz.beams] == [[], [], []]
    assert [(b.range.mean, b.range.variance) for b in gz.beams] == [
        (10.5, 0.125),
        (20.5, 0.25),
        (30.5, 0.375),
    ]
    assert [beam.rssi for beam in gz.beams] == [61.0, 62.0, 63.0]
    assert [beam.nsd for beam in gz.beams] == [0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    ("dvl_type", "gz_type"),
    [
        (Dvl.DVL_TYPE_PISTON, GzDvl.DVL_TYPE_PISTON),
        (Dvl.DVL_TYPE_PHASED_ARRAY, GzDvl.DVL_TYPE_PHASED_ARRAY),
        (2, GzDvl.DVL_TYPE_UNSPECIFIED),
        (255, GzDvl.DVL_TYPE_UNSPECIFIED),
    ],
)
def test_to_gz_dvl_types(dvl_type: int, gz_type: int) -> None:
    ros = ros_dvl()
    ros.dvl_type = dvl_type
    assert conv.dvl_to_gz(ros).type == gz_type


@pytest.mark.parametrize(
    ("mode", "target"),
    [
        (Dvl.DVL_MODE_BOTTOM, GzTarget.DVL_TARGET_BOTTOM),
        (Dvl.DVL_MODE_WATER, GzTarget.DVL_TARGET_WATER_MASS),
        (0, GzTarget.DVL_TARGET_UNSPECIFIED),
        (3, GzTarget.DVL_TARGET_UNSPECIFIED),
    ],
)
def test_to_gz_velocity_modes(mode: int, target: int) -> None:
    ros = ros_dvl()
    ros.velocity_mode = mode
    gz = conv.dvl_to_gz(ros)
    assert gz.HasField("target")
    assert gz.target.type == target


@pytest.mark.parametrize("altitude", [-1.0, -0.001, math.nan])
def test_to_gz_unknown_altitude_leaves_the_target_range_out(altitude: float) -> None:
    ros = ros_dvl()
    ros.altitude = altitude
    assert not conv.dvl_to_gz(ros).target.HasField("range")


def test_to_gz_zero_altitude_is_a_range() -> None:
    ros = ros_dvl()
    ros.altitude = 0.0
    gz = conv.dvl_to_gz(ros)
    assert gz.target.HasField("range")
    assert gz.target.range.mean == 0.0


def test_to_gz_without_good_beams_sends_no_beams() -> None:
    gz = conv.dvl_to_gz(ros_dvl(good_beams=0))
    assert len(gz.beams) == 0
    assert gz.velocity.HasField("mean")


def test_to_gz_four_good_beams_use_all_slots() -> None:
    gz = conv.dvl_to_gz(ros_dvl(good_beams=4))
    assert [beam.range.mean for beam in gz.beams] == [10.5, 20.5, 30.5, 40.5]
    assert xyz(gz.beams[3].velocity.mean) == (0.0, -3.5, -56.0)


@pytest.mark.parametrize("good_beams", [5, 255])
def test_to_gz_more_good_beams_than_slots_is_an_error(good_beams: int) -> None:
    with pytest.raises(ConversionError, match=rf"num_good_beams is {good_beams}"):
        conv.dvl_to_gz(ros_dvl(good_beams=good_beams))


def test_light_tree_of_a_valid_dvl_converts_like_the_rclpy_message() -> None:
    # tests/unit/ros/test_light_reader.py fills num_good_beams with more than 4: only the error
    # path.
    msg = ros_dvl(good_beams=4)
    tree = light_reader.read(serialize_message(msg), Dvl)
    assert tree is not None
    assert conv.dvl_to_gz(tree) == conv.dvl_to_gz(msg)


# --- Gazebo -> ROS --------------------------------------------------------------------------


def test_to_ros_converts_header_modes_velocity_and_derived_values() -> None:
    ros = conv.dvl_to_ros(gz_dvl())
    assert isinstance(ros, Dvl)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (111, 112)
    assert ros.header.frame_id == "sub/dvl"
    assert ros.velocity_mode == Dvl.DVL_MODE_BOTTOM
    assert ros.dvl_type == Dvl.DVL_TYPE_PHASED_ARRAY
    assert xyz(ros.velocity) == (3.0, -4.0, 0.25)
    assert list(ros.velocity_covar) == COVARIANCE
    assert ros.altitude == 23.5
    assert ros.course_gnd == math.atan2(-4.0, 3.0)
    assert ros.speed_gnd == 5.0
    assert ros.sound_speed == -1.0


def test_to_ros_packs_the_locked_beams_among_the_first_four() -> None:
    ros = conv.dvl_to_ros(gz_dvl())
    # Beams 1, 3 and 4 are locked; 2 is not; the fifth does not fit.
    assert ros.num_good_beams == 3
    assert (ros.beam_ranges_valid, ros.beam_velocities_valid) == (True, True)
    assert [xyz(v) for v in ros.beam_unit_vec] == [
        (0.0, 0.6, -0.8),
        (0.0, 0.0, 0.0),
        (-1.0, 0.0, 0.0),
        (0.0, 0.0, 0.0),
    ]
    assert list(ros.beam_velocity) == [5.0, 0.0, 2.0, 0.0]
    assert list(ros.range) == [101.0, 103.0, 104.0, 0.0]
    assert list(ros.range_covar) == [1.25, 3.25, 4.25, 0.0]
    assert list(ros.beam_quality) == [1.5, 3.5, 4.5, 0.0]
    assert list(ros.beam_velocity_covar) == [-1.0, -1.0, -1.0, 0.0]


def test_to_ros_without_locked_beams_has_no_valid_beam_data() -> None:
    gz = gz_dvl()
    for beam in gz.beams:
        beam.locked = False
    ros = conv.dvl_to_ros(gz)
    assert ros.num_good_beams == 0
    assert (ros.beam_ranges_valid, ros.beam_velocities_valid) == (False, False)
    assert list(ros.range) == [0.0] * 4


@pytest.mark.parametrize(
    ("target", "mode"),
    [
        (GzTarget.DVL_TARGET_UNSPECIFIED, Dvl.DVL_MODE_BOTTOM),
        (GzTarget.DVL_TARGET_BOTTOM, Dvl.DVL_MODE_BOTTOM),
        (GzTarget.DVL_TARGET_WATER_MASS, Dvl.DVL_MODE_WATER),
        (9, Dvl.DVL_MODE_BOTTOM),
    ],
)
def test_to_ros_velocity_modes(target: int, mode: int) -> None:
    gz = gz_dvl()
    gz.target.type = target
    assert conv.dvl_to_ros(gz).velocity_mode == mode


@pytest.mark.parametrize(
    ("gz_type", "dvl_type"),
    [
        (GzDvl.DVL_TYPE_UNSPECIFIED, Dvl.DVL_TYPE_PISTON),
        (GzDvl.DVL_TYPE_PISTON, Dvl.DVL_TYPE_PISTON),
        (GzDvl.DVL_TYPE_PHASED_ARRAY, Dvl.DVL_TYPE_PHASED_ARRAY),
        (7, Dvl.DVL_TYPE_PISTON),
    ],
)
def test_to_ros_dvl_types(gz_type: int, dvl_type: int) -> None:
    gz = gz_dvl()
    gz.type = gz_type
    assert conv.dvl_to_ros(gz).dvl_type == dvl_type


def test_to_ros_altitude_only_from_a_positive_bottom_range() -> None:
    gz = gz_dvl()
    gz.target.type = GzTarget.DVL_TARGET_WATER_MASS
    assert conv.dvl_to_ros(gz).altitude == -1.0
    gz.target.type = GzTarget.DVL_TARGET_BOTTOM
    gz.target.range.mean = 0.0
    assert conv.dvl_to_ros(gz).altitude == -1.0
    gz.target.ClearField("range")
    assert conv.dvl_to_ros(gz).altitude == -1.0


def test_to_ros_missing_covariance_values_are_unknown() -> None:
    gz = gz_dvl()
    del gz.velocity.covariance[4:]
    assert list(conv.dvl_to_ros(gz).velocity_covar) == COVARIANCE[:4] + [-1.0] * 5
    gz.velocity.covariance.extend([99.0] * 10)
    assert list(conv.dvl_to_ros(gz).velocity_covar) == COVARIANCE[:4] + [99.0] * 5


def test_to_ros_narrows_beam_values_to_float32() -> None:
    gz = gz_dvl()
    gz.beams[0].rssi = 0.1
    gz.beams[0].range.variance = 1e39
    ros = conv.dvl_to_ros(gz)
    assert ros.beam_quality[0] == np.float32(0.1)
    assert ros.range_covar[0] == np.inf


def test_default_message_converts_both_ways() -> None:
    gz = conv.dvl_to_gz(Dvl())
    assert gz.type == GzDvl.DVL_TYPE_PISTON
    assert gz.target.type == GzTarget.DVL_TARGET_UNSPECIFIED
    assert list(gz.velocity.covariance) == [0.0] * 9
    ros = conv.dvl_to_ros(GzDvl())
    assert (ros.altitude, ros.sound_speed, ros.num_good_beams) == (-1.0, -1.0, 0)
    assert list(ros.velocity_covar) == [-1.0] * 9
