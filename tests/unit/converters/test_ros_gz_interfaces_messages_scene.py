"""ros_gz_interfaces' messages of the scene (converters/ros_gz_interfaces_messages.py,
docs/conversions-per-package.md §3.13): the tracked visual, the GUI camera, lights and material
colours."""

from __future__ import annotations

from typing import Any

import pytest
from ros_gz_interfaces.msg import (
    GuiCamera,
    Light,
    MaterialColor,
    TrackVisual,
)

from ros_gz_bridge_py.converters import ros_gz_interfaces_messages as m
from tests.unit.converters.ros_gz_interfaces_values import (
    GzLight,
    GzMaterialColor,
    assert_stamped,
    assert_vector,
    color,
    entity,
    header,
    pose,
    track_visual,
    vec,
)

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
