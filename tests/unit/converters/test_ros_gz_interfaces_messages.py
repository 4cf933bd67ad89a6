"""ros_gz_interfaces' messages (converters/ros_gz_interfaces_messages.py,
docs/conversions-per-package.md §3.13): entities, wrenches, contacts, the altimeter, data frames,
arrays, sensor noise, video recording and the statistics; the scene's messages and the parameters
have files of their own."""

from __future__ import annotations

import math
from typing import Any

import pytest
from ros_gz_interfaces.msg import (
    Altimeter,
    Contact,
    Contacts,
    Dataframe,
    Entity,
    EntityWrench,
    Float32Array,
    LogPlaybackStatistics,
    SensorNoise,
    StringVec,
    VideoRecord,
    WorldStatistics,
)

from ros_gz_bridge_py.converters import ros_gz_interfaces_messages as m
from tests.unit.converters.ros_gz_interfaces_values import (
    GzDataframe,
    GzEntity,
    GzLogPlaybackStatistics,
    GzSensorNoise,
    assert_stamped,
    assert_vector,
    entity,
    header,
    header_data,
    joint_wrench,
    vec,
)

# --- Entity ---------------------------------------------------------------------------------


def test_entity_converts_and_round_trips() -> None:
    ros = entity()
    gz = m.entity_to_gz(ros)
    assert (gz.id, gz.name, gz.type) == (9_000_000_001, "box::link", GzEntity.LINK)
    assert not gz.HasField("header")
    assert m.entity_to_ros(gz) == ros


@pytest.mark.parametrize("kind", range(8))
def test_entity_types_zero_to_seven_map_by_number(kind: int) -> None:
    assert m.entity_to_gz(entity(kind=kind)).type == kind
    assert m.entity_to_ros(GzEntity(type=kind)).type == kind


def test_unknown_entity_types_fall_back_to_none() -> None:
    assert m.entity_to_gz(entity(kind=8)).type == GzEntity.NONE
    assert m.entity_to_ros(GzEntity(type=GzEntity.ACTOR)).type == Entity.NONE
    assert m.entity_to_ros(GzEntity(type=GzEntity.WORLD)).type == Entity.NONE


# --- EntityWrench, JointWrench --------------------------------------------------------------


def test_entity_wrench_converts_and_round_trips() -> None:
    ros = EntityWrench(header=header(), entity=entity())
    ros.wrench.force = vec(1.5, -2.25, 3.125)
    ros.wrench.torque = vec(-4.5, 5.75, -6.0625)
    gz = m.entity_wrench_to_gz(ros)
    assert_stamped(gz.header)
    assert (gz.entity.id, gz.entity.name, gz.entity.type) == (9_000_000_001, "box::link", 3)
    assert_vector(gz.wrench.force, 1.5, -2.25, 3.125)
    assert_vector(gz.wrench.torque, -4.5, 5.75, -6.0625)
    assert not gz.wrench.HasField("force_offset")
    assert not gz.wrench.HasField("header")
    assert m.entity_wrench_to_ros(gz) == ros


def test_entity_wrench_submessages_present_even_when_default() -> None:
    gz = m.entity_wrench_to_gz(EntityWrench())
    for field in ("header", "entity", "wrench"):
        assert gz.HasField(field)
    assert gz.wrench.HasField("force")
    assert gz.wrench.HasField("torque")


def test_joint_wrench_converts_and_round_trips() -> None:
    ros = joint_wrench(7.0)
    gz = m.joint_wrench_to_gz(ros)
    assert_stamped(gz.header, sec=7)
    assert (gz.body_1_name, gz.body_1_id) == ("body1_7.0", 18)
    assert (gz.body_2_name, gz.body_2_id) == ("body2_7.0", 29)
    assert_vector(gz.body_1_wrench.force, 7.0, -7.0, 14.0)
    assert_vector(gz.body_1_wrench.torque, 7.5, -7.5, 21.0)
    assert_vector(gz.body_2_wrench.force, 7.25, 6.25, 28.0)
    assert_vector(gz.body_2_wrench.torque, 7.125, 6.625, 35.0)
    assert m.joint_wrench_to_ros(gz) == ros


# --- Contact, Contacts ----------------------------------------------------------------------


def contact() -> Any:
    return Contact(
        collision1=entity(11, "a::collision", Entity.COLLISION),
        collision2=entity(22, "b::collision", Entity.VISUAL),
        positions=[vec(1.0, 2.0, 3.0), vec(4.0, 5.0, 6.0)],
        normals=[vec(0.0, 0.0, 1.0)],
        depths=[0.125, 0.25, 0.5],
        wrenches=[joint_wrench(1.0), joint_wrench(2.0)],
    )


def test_contact_uses_collision2_for_collision2() -> None:
    gz = m.contact_to_gz(contact())
    assert (gz.collision1.id, gz.collision1.name, gz.collision1.type) == (11, "a::collision", 5)
    assert (gz.collision2.id, gz.collision2.name, gz.collision2.type) == (22, "b::collision", 4)


def test_contact_converts_every_list_and_round_trips() -> None:
    ros = contact()
    gz = m.contact_to_gz(ros)
    assert [(p.x, p.y, p.z) for p in gz.position] == [(1.0, 2.0, 3.0), (4.0, 5.0, 6.0)]
    assert [(n.x, n.y, n.z) for n in gz.normal] == [(0.0, 0.0, 1.0)]
    assert list(gz.depth) == [0.125, 0.25, 0.5]
    assert [w.body_1_id for w in gz.wrench] == [12, 13]
    assert_stamped(gz.wrench[1].header, sec=2)
    assert not gz.HasField("header")
    assert not gz.HasField("world")
    assert m.contact_to_ros(gz) == ros


def test_default_contact_has_both_collisions_present() -> None:
    gz = m.contact_to_gz(Contact())
    assert gz.HasField("collision1")
    assert gz.HasField("collision2")


def test_contacts_converts_and_round_trips() -> None:
    ros = Contacts(header=header(), contacts=[contact(), Contact()])
    gz = m.contacts_to_gz(ros)
    assert_stamped(gz.header)
    assert len(gz.contact) == 2
    assert gz.contact[0].collision2.name == "b::collision"
    assert m.contacts_to_ros(gz) == ros


# --- Altimeter ------------------------------------------------------------------------------


def test_altimeter_converts_and_round_trips() -> None:
    ros = Altimeter(
        header=header(), vertical_position=1.5, vertical_velocity=-2.25, vertical_reference=3.125
    )
    gz = m.altimeter_to_gz(ros)
    assert_stamped(gz.header)
    assert (gz.vertical_position, gz.vertical_velocity, gz.vertical_reference) == (
        1.5,
        -2.25,
        3.125,
    )
    assert m.altimeter_to_ros(gz) == ros


# --- Dataframe ------------------------------------------------------------------------------


def upstream_dataframe() -> Any:
    return Dataframe(
        header=header(),
        src_address="localhost:8080",
        dst_address="localhost:8081",
        data=b"1" * 150,
        rssi=-10.3,
    )


def test_dataframe_upstream_fixture_converts_to_gz() -> None:
    gz = m.dataframe_to_gz(upstream_dataframe())
    assert header_data(gz.header) == [("frame_id", ["frame_id_value"]), ("rssi", ["-10.300000"])]
    assert (gz.src_address, gz.dst_address) == ("localhost:8080", "localhost:8081")
    assert gz.data == b"1" * 150


def test_dataframe_round_trips() -> None:
    ros = upstream_dataframe()
    assert m.dataframe_to_ros(m.dataframe_to_gz(ros)) == ros


@pytest.mark.parametrize(
    ("rssi", "text"),
    [(0.0, "0.000000"), (1e-7, "0.000000"), (12.3456789, "12.345679"), (math.inf, "inf")],
)
def test_dataframe_rssi_is_formatted_like_printf_f(rssi: float, text: str) -> None:
    gz = m.dataframe_to_gz(Dataframe(rssi=rssi))
    assert list(gz.header.data[1].value) == [text]


def test_dataframe_rssi_last_valid_entry_wins_and_bad_ones_are_skipped() -> None:
    gz = GzDataframe()
    for key, values in [
        ("rssi", ["-3.5"]),
        ("rssi", ["  7.25dBm"]),
        ("rssi", []),
        ("rssi", ["garbage"]),
        ("RSSI", ["99"]),
        ("rssi", ["1e999"]),
    ]:
        entry = gz.header.data.add()
        entry.key = key
        entry.value.extend(values)
    assert m.dataframe_to_ros(gz).rssi == 7.25


def test_dataframe_without_rssi_entry_reads_zero() -> None:
    assert m.dataframe_to_ros(GzDataframe(data=b"\x00\xff")).data.tobytes() == b"\x00\xff"
    assert m.dataframe_to_ros(GzDataframe()).rssi == 0.0


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("-10.300000", -10.3),
        ("\t\n 42", 42.0),
        ("+.5e1x", 5.0),
        ("1.", 1.0),
        ("1e", 1.0),
        ("1e+", 1.0),
        ("0x1.8p1", 3.0),
        ("0x", 0.0),
        ("-0X.8", -0.5),
        ("INFINITY", math.inf),
        ("-inf", -math.inf),
        ("infinit", math.inf),
        ("1e-300", 1e-300),
    ],
)
def test_parse_strtod_accepts_what_strtod_accepts(text: str, expected: float) -> None:
    assert m.parse_strtod(text) == expected


def test_parse_strtod_reads_nan() -> None:
    value = m.parse_strtod("nan(123)")
    assert value is not None
    assert math.isnan(value)


@pytest.mark.parametrize("text", ["", "  ", "abc", "-", ".", "e5", "1e999", "-1e400", "1e-400"])
def test_parse_strtod_rejects_what_stod_throws_on(text: str) -> None:
    assert m.parse_strtod(text) is None


# --- Float32Array, StringVec ----------------------------------------------------------------


def test_float32_array_converts_and_round_trips() -> None:
    ros = Float32Array(data=[1.5, -2.25, 3.125, 0.0])
    gz = m.float32_array_to_gz(ros)
    assert list(gz.data) == [1.5, -2.25, 3.125, 0.0]
    assert not gz.HasField("header")
    assert m.float32_array_to_ros(gz) == ros


def test_string_vec_converts_and_round_trips() -> None:
    ros = StringVec(header=header(), data=["alpha", "", "gamma::delta"])
    gz = m.string_vec_to_gz(ros)
    assert_stamped(gz.header)
    assert list(gz.data) == ["alpha", "", "gamma::delta"]
    assert m.string_vec_to_ros(gz) == ros


# --- SensorNoise, VideoRecord ---------------------------------------------------------------


def test_sensor_noise_converts_all_but_the_correlation_time() -> None:
    ros = SensorNoise(
        header=header(),
        type=SensorNoise.GAUSSIAN_QUANTIZED,
        mean=0.5,
        stddev=1.25,
        bias_mean=-0.75,
        bias_stddev=0.0625,
        precision=0.001,
        dynamic_bias_stddev=2.5,
        dynamic_bias_correlation_time=9.5,
    )
    gz = m.sensor_noise_to_gz(ros)
    assert_stamped(gz.header)
    assert gz.type == GzSensorNoise.GAUSSIAN_QUANTIZED
    assert (gz.mean, gz.stddev, gz.bias_mean, gz.bias_stddev) == (0.5, 1.25, -0.75, 0.0625)
    assert (gz.precision, gz.dynamic_bias_stddev) == (0.001, 2.5)
    assert gz.dynamic_bias_correlation_time == 0.0
    back = m.sensor_noise_to_ros(GzSensorNoise(dynamic_bias_correlation_time=4.0, type=2))
    assert (back.dynamic_bias_correlation_time, back.type) == (0.0, SensorNoise.GAUSSIAN)
    ros.dynamic_bias_correlation_time = 0.0
    assert m.sensor_noise_to_ros(gz) == ros


@pytest.mark.parametrize(("kind", "expected"), [(0, 0), (1, 0), (2, 2), (3, 3), (4, 0)])
def test_sensor_noise_unknown_types_fall_back_to_none(kind: int, expected: int) -> None:
    assert m.sensor_noise_to_gz(SensorNoise(type=kind)).type == expected
    assert m.sensor_noise_to_ros(GzSensorNoise(type=kind)).type == expected


def test_video_record_converts_and_round_trips() -> None:
    ros = VideoRecord(
        header=header(), start=True, stop=False, format="mp4", save_filename="/tmp/out.mp4"
    )
    gz = m.video_record_to_gz(ros)
    assert_stamped(gz.header)
    assert (gz.start, gz.stop, gz.format, gz.save_filename) == (True, False, "mp4", "/tmp/out.mp4")
    assert m.video_record_to_ros(gz) == ros
    stop_only = m.video_record_to_gz(VideoRecord(stop=True))
    assert (stop_only.start, stop_only.stop) == (False, True)


# --- WorldStatistics ------------------------------------------------------------------------


def test_world_statistics_converts_every_field_and_round_trips() -> None:
    ros = WorldStatistics(
        header=header(),
        paused=True,
        iterations=2**40 + 3,
        model_count=-12,
        real_time_factor=0.875,
        stepping=True,
    )
    for offset, name in enumerate(("sim_time", "pause_time", "real_time", "step_size")):
        getattr(ros, name).sec = 100 + offset
        getattr(ros, name).nanosec = 1000 + offset
    log = ros.log_playback_statistics
    log.header = header(44, "log")
    log.start_time.sec, log.start_time.nanosec = 5, 6
    log.end_time.sec, log.end_time.nanosec = 7, 3_000_000_000
    gz = m.world_statistics_to_gz(ros)
    assert_stamped(gz.header)
    times = [(t.sec, t.nsec) for t in (gz.sim_time, gz.pause_time, gz.real_time, gz.step_size)]
    assert times == [(100, 1000), (101, 1001), (102, 1002), (103, 1003)]
    assert (gz.paused, gz.iterations, gz.model_count) == (True, 2**40 + 3, -12)
    assert (gz.real_time_factor, gz.stepping) == (0.875, True)
    assert_stamped(gz.log_playback_stats.header, sec=44, frame="log")
    assert (gz.log_playback_stats.start_time.sec, gz.log_playback_stats.start_time.nsec) == (5, 6)
    assert gz.log_playback_stats.end_time.nsec == 3_000_000_000 - 2**32
    assert m.world_statistics_to_ros(gz) == ros


def test_default_world_statistics_has_every_submessage() -> None:
    gz = m.world_statistics_to_gz(WorldStatistics())
    for field in ("header", "sim_time", "pause_time", "real_time", "step_size"):
        assert gz.HasField(field)
    log = gz.log_playback_stats
    assert log.HasField("header")
    assert log.HasField("start_time")
    assert log.HasField("end_time")


# --- LogPlaybackStatistics ------------------------------------------------------------------


def test_log_playback_statistics_to_gz_keeps_start_and_end_apart() -> None:
    ros = LogPlaybackStatistics(header=header(61, "log"))
    ros.start_time.sec, ros.start_time.nanosec = 1_700_000_000, 250
    ros.end_time.sec, ros.end_time.nanosec = 1_700_000_360, 4_000_000_000
    gz = m.log_playback_statistics_to_gz(ros)
    assert_stamped(gz.header, sec=61, frame="log")
    assert (gz.start_time.sec, gz.start_time.nsec) == (1_700_000_000, 250)
    # nanosec is reinterpreted as int32 (docs/conversions.md §1.2).
    assert (gz.end_time.sec, gz.end_time.nsec) == (1_700_000_360, 4_000_000_000 - 2**32)
    assert m.log_playback_statistics_to_ros(gz) == ros


def test_log_playback_statistics_to_ros_keeps_start_and_end_apart() -> None:
    gz = GzLogPlaybackStatistics()
    gz.header.stamp.sec, gz.header.stamp.nsec = 71, 72
    gz.header.data.add(key="frame_id", value=["world::log"])
    gz.start_time.sec, gz.start_time.nsec = -5, 6
    gz.end_time.sec, gz.end_time.nsec = 2**31 + 7, -8
    ros = m.log_playback_statistics_to_ros(gz)
    assert isinstance(ros, LogPlaybackStatistics)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (71, 72)
    assert ros.header.frame_id == "world/log"
    assert (ros.start_time.sec, ros.start_time.nanosec) == (-5, 6)
    # sec narrows to int32 and a negative nsec wraps to uint32, without normalising (§1.2).
    assert (ros.end_time.sec, ros.end_time.nanosec) == (-(2**31) + 7, 2**32 - 8)


def test_default_log_playback_statistics_sends_both_times() -> None:
    gz = m.log_playback_statistics_to_gz(LogPlaybackStatistics())
    for field in ("header", "start_time", "end_time"):
        assert gz.HasField(field)
