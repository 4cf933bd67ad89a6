"""ros_gz_interfaces message pairs and the four services (docs/conversions.md §3.13, §3.14)."""

from __future__ import annotations

import math
from typing import Any

import pytest
from geometry_msgs.msg import Pose, Vector3
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from ros_gz_interfaces.msg import (
    Altimeter,
    Contact,
    Contacts,
    Dataframe,
    Entity,
    EntityFactory,
    EntityWrench,
    Float32Array,
    GuiCamera,
    JointWrench,
    Light,
    LogPlaybackStatistics,
    MaterialColor,
    ParamVec,
    SensorNoise,
    StringVec,
    TrackVisual,
    VideoRecord,
    WorldControl,
    WorldStatistics,
)
from ros_gz_interfaces.srv import ControlWorld, DeleteEntity, SetEntityPose, SpawnEntity
from std_msgs.msg import ColorRGBA, Header

from ros_gz_bridge_py.converters import ros_gz_interfaces_messages as m
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.converters.ros_gz_interfaces import (
    PAIRS,
    SERVICES,
    control_world_request_to_gz,
    delete_entity_request_to_gz,
    set_entity_pose_request_to_gz,
    spawn_entity_request_to_gz,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzAny = message_class("gz.msgs.Any")
GzBoolean = message_class("gz.msgs.Boolean")
GzDataframe = message_class("gz.msgs.Dataframe")
GzEntity = message_class("gz.msgs.Entity")
GzLight = message_class("gz.msgs.Light")
GzLogPlaybackStatistics = message_class("gz.msgs.LogPlaybackStatistics")
GzMaterialColor = message_class("gz.msgs.MaterialColor")
GzParam = message_class("gz.msgs.Param")
GzParamV = message_class("gz.msgs.Param_V")
GzSensorNoise = message_class("gz.msgs.SensorNoise")


# --- builders with a distinct value in every field ------------------------------------------


def header(sec: int = 2, frame: str = "frame_id_value") -> Any:
    ros = Header(frame_id=frame)
    ros.stamp.sec = sec
    ros.stamp.nanosec = 3
    return ros


def vec(x: float, y: float, z: float) -> Any:
    return Vector3(x=x, y=y, z=z)


def pose(base: float) -> Any:
    ros = Pose()
    ros.position.x, ros.position.y, ros.position.z = base, base + 0.5, base + 0.25
    o = ros.orientation
    o.x, o.y, o.z, o.w = base + 1, base + 2, base + 3, base + 4
    return ros


def color(base: float) -> Any:
    return ColorRGBA(r=base, g=base + 0.125, b=base + 0.25, a=base + 0.375)


def entity(id_: int = 9_000_000_001, name: str = "box::link", kind: int = Entity.LINK) -> Any:
    return Entity(id=id_, name=name, type=kind)


def joint_wrench(base: float) -> Any:
    ros = JointWrench(header=header(int(base)))
    ros.body_1_name.data = f"body1_{base}"
    ros.body_1_id.data = int(base) + 11
    ros.body_2_name.data = f"body2_{base}"
    ros.body_2_id.data = int(base) + 22
    ros.body_1_wrench.force = vec(base, -base, 2 * base)
    ros.body_1_wrench.torque = vec(base + 0.5, -base - 0.5, 3 * base)
    ros.body_2_wrench.force = vec(base + 0.25, base - 0.75, 4 * base)
    ros.body_2_wrench.torque = vec(base + 0.125, base - 0.375, 5 * base)
    return ros


def track_visual() -> Any:
    return TrackVisual(
        header=header(5, "tracked"),
        name="visual_name",
        id=4242,
        inherit_orientation=True,
        min_dist=1.5,
        max_dist=22.25,
        is_static=True,
        use_model_frame=True,
        xyz=vec(0.5, -1.5, 2.5),
        inherit_yaw=True,
    )


def header_data(gz_header: Any) -> list[tuple[str, list[str]]]:
    return [(entry.key, list(entry.value)) for entry in gz_header.data]


def assert_stamped(gz_header: Any, sec: int = 2, frame: str = "frame_id_value") -> None:
    assert gz_header.HasField("stamp")
    assert (gz_header.stamp.sec, gz_header.stamp.nsec) == (sec, 3)
    assert header_data(gz_header) == [("frame_id", [frame])]


def assert_vector(gz: Any, x: float, y: float, z: float) -> None:
    assert (gz.x, gz.y, gz.z) == (x, y, z)


# --- registration ---------------------------------------------------------------------------


def test_every_pair_and_service_registers_once() -> None:
    registry = Registry()
    for pair in PAIRS:
        registry.add(pair)
    for service in SERVICES:
        registry.add_service(service)
    assert registry.gz_types_for("ros_gz_interfaces/msg/ParamVec") == [
        "gz.msgs.Param",
        "gz.msgs.Param_V",
    ]
    assert [s.ros_type for s in SERVICES] == [
        "ros_gz_interfaces/srv/ControlWorld",
        "ros_gz_interfaces/srv/DeleteEntity",
        "ros_gz_interfaces/srv/SpawnEntity",
        "ros_gz_interfaces/srv/SetEntityPose",
    ]
    for pair in PAIRS:
        assert message_class(pair.gz_type).DESCRIPTOR.full_name == pair.gz_type
        assert isinstance(pair.to_ros(message_class(pair.gz_type)()), pair.ros_class)


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


# --- TrackVisual, GuiCamera -----------------------------------------------------------------


def test_track_visual_converts_and_round_trips() -> None:
    ros = track_visual()
    gz = m.track_visual_to_gz(ros)
    assert_stamped(gz.header, sec=5, frame="tracked")
    assert (gz.name, gz.id, gz.inherit_orientation) == ("visual_name", 4242, True)
    assert (gz.min_dist, gz.max_dist) == (1.5, 22.25)
    assert (gz.static, gz.use_model_frame, gz.inherit_yaw) == (True, True, True)
    assert_vector(gz.xyz, 0.5, -1.5, 2.5)
    assert m.track_visual_to_ros(gz) == ros


def test_track_visual_flags_are_not_swapped() -> None:
    for flag in ("inherit_orientation", "is_static", "use_model_frame", "inherit_yaw"):
        back = m.track_visual_to_ros(m.track_visual_to_gz(TrackVisual(**{flag: True})))
        assert [
            f
            for f in ("inherit_orientation", "is_static", "use_model_frame", "inherit_yaw")
            if getattr(back, f)
        ] == [flag]


def test_gui_camera_converts_and_round_trips() -> None:
    ros = GuiCamera(
        header=header(),
        name="user_camera",
        view_controller="orbit",
        pose=pose(1.5),
        track=track_visual(),
        projection_type="orthographic",
    )
    gz = m.gui_camera_to_gz(ros)
    assert_stamped(gz.header)
    assert (gz.name, gz.view_controller, gz.projection_type) == (
        "user_camera",
        "orbit",
        "orthographic",
    )
    assert_vector(gz.pose.position, 1.5, 2.0, 1.75)
    assert (gz.pose.orientation.x, gz.pose.orientation.w) == (2.5, 5.5)
    assert not gz.pose.HasField("header")
    assert gz.track.name == "visual_name"
    assert_stamped(gz.track.header, sec=5, frame="tracked")
    assert m.gui_camera_to_ros(gz) == ros


def test_default_gui_camera_has_its_submessages() -> None:
    gz = m.gui_camera_to_gz(GuiCamera())
    assert gz.HasField("header")
    assert gz.pose.HasField("position")
    assert gz.pose.HasField("orientation")
    assert gz.track.HasField("header")
    assert gz.track.HasField("xyz")


# --- Light ----------------------------------------------------------------------------------


def light() -> Any:
    return Light(
        header=header(),
        name="sun",
        type=Light.SPOT,
        pose=pose(2.0),
        diffuse=color(0.125),
        specular=color(0.5),
        attenuation_constant=0.75,
        attenuation_linear=0.0625,
        attenuation_quadratic=0.03125,
        direction=vec(-0.5, 0.25, -1.0),
        range=120.5,
        cast_shadows=True,
        spot_inner_angle=0.25,
        spot_outer_angle=0.75,
        spot_falloff=1.5,
        id=77,
        parent_id=88,
        intensity=2.5,
    )


def test_light_converts_and_round_trips() -> None:
    ros = light()
    gz = m.light_to_gz(ros)
    assert_stamped(gz.header)
    assert (gz.name, gz.type) == ("sun", GzLight.SPOT)
    assert_vector(gz.pose.position, 2.0, 2.5, 2.25)
    assert (gz.diffuse.r, gz.diffuse.g, gz.diffuse.b, gz.diffuse.a) == (0.125, 0.25, 0.375, 0.5)
    assert (gz.specular.r, gz.specular.a) == (0.5, 0.875)
    assert (gz.attenuation_constant, gz.attenuation_linear, gz.attenuation_quadratic) == (
        0.75,
        0.0625,
        0.03125,
    )
    assert_vector(gz.direction, -0.5, 0.25, -1.0)
    assert (gz.range, gz.cast_shadows) == (120.5, True)
    assert (gz.spot_inner_angle, gz.spot_outer_angle, gz.spot_falloff) == (0.25, 0.75, 1.5)
    assert (gz.id, gz.parent_id, gz.intensity) == (77, 88, 2.5)
    assert (gz.is_light_off, gz.visualize_visual) == (False, False)
    assert m.light_to_ros(gz) == ros


def test_default_light_has_its_submessages() -> None:
    gz = m.light_to_gz(Light())
    for field in ("header", "pose", "diffuse", "specular", "direction"):
        assert gz.HasField(field)


@pytest.mark.parametrize(("ros_type", "gz_type"), [(0, 0), (1, 1), (2, 2), (3, 0), (200, 0)])
def test_light_type_falls_back_to_point(ros_type: int, gz_type: int) -> None:
    assert m.light_to_gz(Light(type=ros_type)).type == gz_type


def test_unknown_gz_light_type_reads_point() -> None:
    assert m.light_to_ros(GzLight(type=9)).type == Light.POINT


# --- MaterialColor --------------------------------------------------------------------------


def test_material_color_converts_and_round_trips() -> None:
    ros = MaterialColor(
        header=header(),
        entity=entity(),
        ambient=color(0.0),
        diffuse=color(0.125),
        specular=color(0.25),
        emissive=color(0.5),
        shininess=3.75,
        entity_match=MaterialColor.ALL,
    )
    gz = m.material_color_to_gz(ros)
    assert_stamped(gz.header)
    assert gz.entity.name == "box::link"
    assert [c.r for c in (gz.ambient, gz.diffuse, gz.specular, gz.emissive)] == [
        0.0,
        0.125,
        0.25,
        0.5,
    ]
    assert gz.emissive.a == 0.875
    assert (gz.shininess, gz.entity_match) == (3.75, GzMaterialColor.ALL)
    assert m.material_color_to_ros(gz) == ros


def test_default_material_color_has_its_submessages() -> None:
    gz = m.material_color_to_gz(MaterialColor())
    for field in ("header", "entity", "ambient", "diffuse", "specular", "emissive"):
        assert gz.HasField(field)


def test_unknown_entity_match_falls_back_to_first() -> None:
    assert m.material_color_to_gz(MaterialColor(entity_match=5)).entity_match == 0
    assert m.material_color_to_ros(GzMaterialColor(entity_match=5)).entity_match == 0


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


# --- ParamVec <-> Param, Param_V ------------------------------------------------------------


def string_param(name: str, text: str) -> Any:
    return Parameter(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=text)
    )


def test_param_vec_to_param_upstream_fixture() -> None:
    ros = ParamVec(
        header=header(), params=[string_param("parameter_name_foo", "parameter_value_foo")]
    )
    gz = m.param_vec_to_gz_param(ros)
    assert_stamped(gz.header)
    assert list(gz.params) == ["parameter_name_foo"]
    value = gz.params["parameter_name_foo"]
    assert (value.type, value.string_value) == (GzAny.STRING, "parameter_value_foo")
    assert len(gz.children) == 0
    assert m.param_vec_from_gz_param(gz) == ros


def test_param_vec_duplicate_name_overwrites() -> None:
    double = Parameter(
        name="dup", value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=2.5)
    )
    gz = m.param_vec_to_gz_param(ParamVec(params=[string_param("dup", "first"), double]))
    assert gz.params["dup"].WhichOneof("value") == "double_value"
    assert gz.params["dup"].double_value == 2.5


def upstream_param_tree() -> Any:
    """Map entries plus nested children, as in the upstream G→R test."""
    gz = GzParam()
    gz.params["notset_param"].type = GzAny.NONE
    child0 = gz.children.add()
    child0.params["int_param"].type = GzAny.INT32
    child0.params["int_param"].int_value = 100
    child1 = gz.children.add()
    child1.params["double_param"].type = GzAny.DOUBLE
    child1.params["double_param"].double_value = 200.5
    child2 = gz.children.add()
    child2.header.data.add(key="frame_id", value=["ignored"])
    child2.params["string_param"].type = GzAny.STRING
    child2.params["string_param"].string_value = "foo"
    grandchild = child2.children.add()
    grandchild.params["bool_param"].type = GzAny.BOOLEAN
    grandchild.params["bool_param"].bool_value = True
    return gz


def test_param_children_are_flattened_with_prefixes() -> None:
    ros = m.param_vec_from_gz_param(upstream_param_tree())
    assert [p.name for p in ros.params] == [
        "notset_param",
        "child_0/int_param",
        "child_1/double_param",
        "child_2/string_param",
        "child_2/child_0/bool_param",
    ]
    values = [p.value for p in ros.params]
    assert values[0].type == ParameterType.PARAMETER_NOT_SET
    assert (values[1].type, values[1].integer_value) == (ParameterType.PARAMETER_INTEGER, 100)
    assert values[2].double_value == 200.5
    assert values[3].string_value == "foo"
    assert (values[4].type, values[4].bool_value) == (ParameterType.PARAMETER_BOOL, True)
    assert ros.header.frame_id == ""


def test_param_map_entries_are_sorted_by_key() -> None:
    gz = GzParam()
    for key in ("zeta", "alpha", "mid"):
        gz.params[key].type = GzAny.INT32
    assert [p.name for p in m.param_vec_from_gz_param(gz).params] == ["alpha", "mid", "zeta"]


def test_param_vec_to_param_v_puts_everything_in_param_0() -> None:
    ros = ParamVec(header=header(), params=[string_param("a", "x"), string_param("b", "y")])
    gz = m.param_vec_to_gz_param_v(ros)
    assert_stamped(gz.header)
    assert len(gz.param) == 1
    assert_stamped(gz.param[0].header)
    assert sorted(gz.param[0].params) == ["a", "b"]
    back = m.param_vec_from_gz_param_v(gz)
    assert back.header == ros.header
    assert [p.name for p in back.params] == ["param_0/a", "param_0/b"]
    assert [p.value.string_value for p in back.params] == ["x", "y"]


def test_param_v_flattens_each_param_with_children() -> None:
    gz = GzParamV()
    gz.param.add().params["first"].type = GzAny.NONE
    gz.param.append(upstream_param_tree())
    names = [p.name for p in m.param_vec_from_gz_param_v(gz).params]
    assert names == [
        "param_0/first",
        "param_1/notset_param",
        "param_1/child_0/int_param",
        "param_1/child_1/double_param",
        "param_1/child_2/string_param",
        "param_1/child_2/child_0/bool_param",
    ]


# --- Services -------------------------------------------------------------------------------


def test_control_world_request_converts_every_field() -> None:
    control = WorldControl(pause=True, step=False, multi_step=17, seed=4_000_000_000)
    control.reset.all = False
    control.reset.time_only = True
    control.reset.model_only = False
    control.run_to_sim_time.sec = 12
    control.run_to_sim_time.nanosec = 3_000_000_000
    gz = control_world_request_to_gz(ControlWorld.Request(world_control=control))
    assert (gz.pause, gz.step, gz.multi_step, gz.seed) == (True, False, 17, 4_000_000_000)
    assert (gz.reset.all, gz.reset.time_only, gz.reset.model_only) == (False, True, False)
    assert (gz.run_to_sim_time.sec, gz.run_to_sim_time.nsec) == (12, 3_000_000_000 - 2**32)
    assert not gz.HasField("header")


def test_control_world_request_default_has_reset_and_run_to_sim_time() -> None:
    gz = control_world_request_to_gz(ControlWorld.Request())
    assert gz.HasField("reset")
    assert gz.HasField("run_to_sim_time")
    assert gz.SerializeToString() == bytes.fromhex("2a003a00")


def test_delete_entity_request_converts_the_entity() -> None:
    gz = delete_entity_request_to_gz(DeleteEntity.Request(entity=entity(kind=Entity.MODEL)))
    assert (gz.id, gz.name, gz.type) == (9_000_000_001, "box::link", GzEntity.MODEL)


def spawn_request(**fields: Any) -> Any:
    factory = EntityFactory(name="robot", allow_renaming=True, pose=pose(3.0), **fields)
    factory.relative_to = "ground"
    return SpawnEntity.Request(entity_factory=factory)


def test_spawn_entity_request_converts_every_field() -> None:
    gz = spawn_entity_request_to_gz(spawn_request(sdf="<sdf version='1.9'/>"))
    assert (gz.name, gz.allow_renaming, gz.relative_to) == ("robot", True, "ground")
    assert gz.WhichOneof("from") == "sdf"
    assert gz.sdf == "<sdf version='1.9'/>"
    assert_vector(gz.pose.position, 3.0, 3.5, 3.25)
    o = gz.pose.orientation
    assert (o.x, o.y, o.z, o.w) == (4.0, 5.0, 6.0, 7.0)
    assert not gz.HasField("header")


def test_spawn_entity_default_relative_to_is_world() -> None:
    request = SpawnEntity.Request()
    request.entity_factory.clone_name = "original"
    gz = spawn_entity_request_to_gz(request)
    assert gz.relative_to == "world"
    assert gz.pose.HasField("orientation")
    assert gz.pose.orientation.w == 1.0


@pytest.mark.parametrize(
    ("fields", "member", "expected"),
    [
        ({"sdf": "s", "sdf_filename": "f", "clone_name": "c"}, "sdf", "s"),
        ({"sdf_filename": "model.sdf", "clone_name": "c"}, "sdf_filename", "model.sdf"),
        ({"clone_name": "existing"}, "clone_name", "existing"),
    ],
)
def test_spawn_entity_source_precedence(fields: dict[str, str], member: str, expected: str) -> None:
    gz = spawn_entity_request_to_gz(spawn_request(**fields))
    assert gz.WhichOneof("from") == member
    assert getattr(gz, member) == expected


def test_spawn_entity_without_source_raises() -> None:
    with pytest.raises(ConversionError, match="sdf, sdf_filename or clone_name"):
        spawn_entity_request_to_gz(spawn_request())


def test_set_entity_pose_request_merges_entity_and_pose() -> None:
    request = SetEntityPose.Request(entity=entity(id_=4_000_000_000, name="box"), pose=pose(-1.0))
    gz = set_entity_pose_request_to_gz(request)
    assert (gz.id, gz.name) == (4_000_000_000, "box")
    assert_vector(gz.position, -1.0, -0.5, -0.75)
    assert (gz.orientation.x, gz.orientation.y, gz.orientation.z, gz.orientation.w) == (
        0.0,
        1.0,
        2.0,
        3.0,
    )
    assert not gz.HasField("header")


def test_set_entity_pose_rejects_an_id_beyond_uint32() -> None:
    request = SetEntityPose.Request(entity=entity(id_=2**32))
    with pytest.raises(ConversionError, match="4294967296"):
        set_entity_pose_request_to_gz(request)


@pytest.mark.parametrize("service", SERVICES, ids=lambda s: s.ros_type)
def test_service_replies_and_failures(service: Any) -> None:
    assert service.gz_rep_type == "gz.msgs.Boolean"
    response_class = service.ros_class.Response
    ok = service.reply_to_ros(GzBoolean(data=True))
    assert isinstance(ok, response_class)
    assert ok.success is True
    assert service.reply_to_ros(GzBoolean(data=False)).success is False
    failure = service.failure_to_ros()
    assert isinstance(failure, response_class)
    assert failure.success is False
    request = service.request_to_gz(_valid_request(service.ros_class))
    assert request.DESCRIPTOR.full_name == service.gz_req_type


def _valid_request(srv_class: Any) -> Any:
    request = srv_class.Request()
    if srv_class is SpawnEntity:
        request.entity_factory.sdf_filename = "model.sdf"
    return request


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
