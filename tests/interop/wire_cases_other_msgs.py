"""The Gazebo -> ROS wire cases of ros_gz_interfaces, vision_msgs, gps_msgs, actuator_msgs,
trajectory_msgs and rcl_interfaces: a text a real publisher sends, and the checks of the ROS
message it must become (the sections of docs/conversions.md and
docs/conversions-per-package.md in the headings)."""

from __future__ import annotations

import math
from typing import Any

from actuator_msgs.msg import Actuators
from gps_msgs.msg import GPSFix, GPSStatus
from rcl_interfaces.msg import ParameterType, ParameterValue
from ros_gz_interfaces.msg import (
    Contacts,
    Entity,
    Float32Array,
    Light,
    LogicalCameraImage,
    LogPlaybackStatistics,
    ParamVec,
    StringVec,
)
from trajectory_msgs.msg import JointTrajectory
from vision_msgs.msg import Detection2D

from tests.interop.wire_case import Case, assert_header, f32, header, xyz, xyzw

# --- ros_gz_interfaces (docs/conversions-per-package.md §3.13) ------------------------------------


def check_entity(ros: Any) -> None:
    assert isinstance(ros, Entity)
    assert ros.id == 123_456_789_012
    assert ros.name == "box::link"
    assert ros.type == Entity.LINK


CONTACTS_TEXT = (
    header("world") + " contact {"
    ' collision1 { id: 11 name: "box::link::collision" type: COLLISION }'
    ' collision2 { id: 22 name: "ground::link::collision" type: COLLISION }'
    " position { x: 1 y: 2 z: 0 } position { x: 1.5 y: 2.5 z: 0 }"
    " normal { x: 0 y: 0 z: 1 }"
    " depth: 0.01 depth: 0.02"
    " wrench { "
    + header("contact", 3, 4)
    + ' body_1_name: "box" body_1_id: 11 body_2_name: "ground" body_2_id: 22'
    " body_1_wrench { force { x: 0.5 y: 0 z: -9.5 } torque { x: 0.25 y: 0 z: 0 } }"
    " body_2_wrench { force { x: -0.5 y: 0 z: 9.5 } torque { x: 0 y: -0.25 z: 0 } } }"
    ' world { id: 1 name: "default" type: MODEL } }'
)


def check_contacts(ros: Any) -> None:
    assert isinstance(ros, Contacts)
    assert_header(ros, "world")
    assert len(ros.contacts) == 1
    contact = ros.contacts[0]
    assert (contact.collision1.id, contact.collision1.name, contact.collision1.type) == (
        11,
        "box::link::collision",
        Entity.COLLISION,
    )
    assert (contact.collision2.id, contact.collision2.name) == (22, "ground::link::collision")
    assert [xyz(p) for p in contact.positions] == [(1.0, 2.0, 0.0), (1.5, 2.5, 0.0)]
    assert [xyz(n) for n in contact.normals] == [(0.0, 0.0, 1.0)]
    assert list(contact.depths) == [0.01, 0.02]
    assert len(contact.wrenches) == 1
    wrench = contact.wrenches[0]
    assert_header(wrench, "contact", 3, 4)
    assert (wrench.body_1_name.data, wrench.body_1_id.data) == ("box", 11)
    assert (wrench.body_2_name.data, wrench.body_2_id.data) == ("ground", 22)
    assert xyz(wrench.body_1_wrench.force) == (0.5, 0.0, -9.5)
    assert xyz(wrench.body_1_wrench.torque) == (0.25, 0.0, 0.0)
    assert xyz(wrench.body_2_wrench.force) == (-0.5, 0.0, 9.5)
    assert xyz(wrench.body_2_wrench.torque) == (0.0, -0.25, 0.0)


LIGHT_TEXT = (
    header("lights") + ' name: "spot::lamp" type: SPOT'
    " pose { position { x: 1 y: 2 z: 3 } orientation { x: 0 y: 0 z: 0 w: 1 } }"
    " diffuse { r: 0.25 g: 0.5 b: 0.75 a: 1 } specular { r: 0.125 g: 0.25 b: 0.5 a: 0.75 }"
    " attenuation_constant: 0.5 attenuation_linear: 0.25 attenuation_quadratic: 0.125"
    " direction { x: 0 y: 0.5 z: -1 } range: 20 cast_shadows: true"
    " spot_inner_angle: 0.5 spot_outer_angle: 1 spot_falloff: 2"
    " id: 7 parent_id: 3 intensity: 1.5"
)


def check_light(ros: Any) -> None:
    assert isinstance(ros, Light)
    assert_header(ros, "lights")
    assert ros.name == "spot::lamp"
    assert ros.type == Light.SPOT
    assert xyz(ros.pose.position) == (1.0, 2.0, 3.0)
    assert xyzw(ros.pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    assert (ros.diffuse.r, ros.diffuse.g, ros.diffuse.b, ros.diffuse.a) == (0.25, 0.5, 0.75, 1.0)
    specular = (ros.specular.r, ros.specular.g, ros.specular.b, ros.specular.a)
    assert specular == (0.125, 0.25, 0.5, 0.75)
    attenuation = (ros.attenuation_constant, ros.attenuation_linear, ros.attenuation_quadratic)
    assert attenuation == (0.5, 0.25, 0.125)
    assert xyz(ros.direction) == (0.0, 0.5, -1.0)
    assert (ros.range, ros.cast_shadows) == (20.0, True)
    assert (ros.spot_inner_angle, ros.spot_outer_angle, ros.spot_falloff) == (0.5, 1.0, 2.0)
    assert (ros.id, ros.parent_id, ros.intensity) == (7, 3, 1.5)


PARAM_TEXT = (
    header("params") + ' params { key: "b_int" value { type: INT32 int_value: -7 } }'
    ' params { key: "a_str" value { type: STRING string_value: "x y" } }'
    " children { "
    + header("child_header_ignored")
    + ' params { key: "flag" value { type: BOOLEAN bool_value: true } } }'
)


def check_param(ros: Any) -> None:
    assert isinstance(ros, ParamVec)
    assert_header(ros, "params")
    names = [p.name for p in ros.params]
    # Map entries first (their order is unspecified), then each child with `child_<c>/`.
    assert sorted(names[:2]) == ["a_str", "b_int"]
    assert names[2:] == ["child_0/flag"]
    values = {p.name: p.value for p in ros.params}
    assert (values["b_int"].type, values["b_int"].integer_value) == (
        ParameterType.PARAMETER_INTEGER,
        -7,
    )
    assert (values["a_str"].type, values["a_str"].string_value) == (
        ParameterType.PARAMETER_STRING,
        "x y",
    )
    flag = values["child_0/flag"]
    assert (flag.type, flag.bool_value) == (ParameterType.PARAMETER_BOOL, True)


def check_string_v(ros: Any) -> None:
    assert isinstance(ros, StringVec)
    assert_header(ros, "strings")
    assert list(ros.data) == ["first", "b::c", "", "ünïcode"]


def check_float_v(ros: Any) -> None:
    assert isinstance(ros, Float32Array)
    assert list(ros.data) == [1.5, -2.25, 1024.0, f32(0.1)]


LOGICAL_CAMERA_TEXT = (
    header("robot::camera")
    + " pose { position { x: 1.5 y: -2.5 z: 0.75 } orientation { x: 0 y: 0 z: 0.6 w: 0.8 } }"
    ' model { name: "cone::yellow" pose { position { x: 4 y: 5 z: 6 } orientation { w: 1 } } }'
    ' model { name: "box" pose { position { x: -7 } } }'
)


def check_logical_camera(ros: Any) -> None:
    assert isinstance(ros, LogicalCameraImage)
    assert_header(ros, "robot/camera")
    assert xyz(ros.pose.position) == (1.5, -2.5, 0.75)
    assert xyzw(ros.pose.orientation) == (0.0, 0.0, 0.6, 0.8)
    # Model names are names, not frames: `::` stays.
    assert [model.name for model in ros.model] == ["cone::yellow", "box"]
    assert xyz(ros.model[0].pose.position) == (4.0, 5.0, 6.0)
    assert xyzw(ros.model[0].pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    assert xyz(ros.model[1].pose.position) == (-7.0, 0.0, 0.0)
    # No orientation on the wire: proto3 w defaults to 0 (§1.4 pitfall).
    assert xyzw(ros.model[1].pose.orientation) == (0.0, 0.0, 0.0, 0.0)


def check_log_playback(ros: Any) -> None:
    assert isinstance(ros, LogPlaybackStatistics)
    assert_header(ros, "log")
    assert (ros.start_time.sec, ros.start_time.nanosec) == (1_700_000_000, 5)
    assert (ros.end_time.sec, ros.end_time.nanosec) == (1_700_000_360, 999_999_999)


# --- vision, gps, actuators, trajectory, rcl (§3.6, §3.9-§3.12) ----------------------------------


def check_detection_2d(ros: Any) -> None:
    assert isinstance(ros, Detection2D)
    assert_header(ros, "camera")
    assert len(ros.results) == 1
    hypothesis = ros.results[0].hypothesis
    assert (hypothesis.class_id, hypothesis.score) == ("42", 1.0)
    assert xyzw(ros.results[0].pose.pose.orientation) == (0.0, 0.0, 0.0, 1.0)
    center = ros.bbox.center
    assert (center.position.x, center.position.y, center.theta) == (3.0, 4.0, 0.0)
    assert (ros.bbox.size_x, ros.bbox.size_y) == (2.0, 4.0)
    assert ros.id == ""


def check_gps_fix(ros: Any) -> None:
    assert isinstance(ros, GPSFix)
    assert_header(ros, "gps/antenna")
    assert (ros.latitude, ros.longitude, ros.altitude) == (-33.8688, 151.2093, 58.25)
    # speed/track from the ENU velocity, track in radians from East (§3.6).
    assert ros.speed == 5.0
    assert ros.track == math.atan2(4.0, 3.0)
    assert ros.climb == -0.5
    assert ros.status.status == GPSStatus.STATUS_GBAS_FIX
    assert ros.position_covariance_type == GPSFix.COVARIANCE_TYPE_UNKNOWN
    assert list(ros.position_covariance) == [0.0] * 9


def check_actuators(ros: Any) -> None:
    assert isinstance(ros, Actuators)
    assert_header(ros, "base")
    assert list(ros.position) == [0.5, -0.5]
    assert list(ros.velocity) == [100.25, 200.5, -300.75]
    assert list(ros.normalized) == [0.125]


def check_joint_trajectory(ros: Any) -> None:
    assert isinstance(ros, JointTrajectory)
    assert_header(ros, "arm_base")
    assert list(ros.joint_names) == ["joint_1", "joint_2"]
    assert len(ros.points) == 2
    first, second = ros.points
    assert (list(first.positions), list(first.velocities)) == ([0.5, 1.5], [])
    assert (list(first.accelerations), list(first.effort)) == ([0.25], [4.0, 5.0])
    # time_from_start is normalised (§3.9): 3 s + 1.25e9 ns = 4.25 s. nsec is first read as
    # uint32, so -0.25e9 ns counts as 4044967296 ns: 2 s + that = 6.044967296 s.
    assert first.time_from_start.sec == 4
    assert first.time_from_start.nanosec == 250_000_000
    assert list(second.positions) == [-0.5, -1.5]
    assert (second.time_from_start.sec, second.time_from_start.nanosec) == (6, 44_967_296)


def check_any(ros: Any) -> None:
    assert isinstance(ros, ParameterValue)
    assert ros.type == ParameterType.PARAMETER_DOUBLE
    assert ros.double_value == 2.718281828
    assert (ros.integer_value, ros.string_value, ros.bool_value) == (0, "", False)


CASES = (
    Case("entity", "ignition.msgs.Entity", "ros_gz_interfaces/msg/Entity",
         'id: 123456789012 name: "box::link" type: LINK', check_entity),
    Case("contacts", "ignition.msgs.Contacts", "ros_gz_interfaces/msg/Contacts",
         CONTACTS_TEXT, check_contacts),
    Case("light", "ignition.msgs.Light", "ros_gz_interfaces/msg/Light", LIGHT_TEXT, check_light),
    Case("param", "ignition.msgs.Param", "ros_gz_interfaces/msg/ParamVec",
         PARAM_TEXT, check_param),
    Case("string_v", "ignition.msgs.StringMsg_V", "ros_gz_interfaces/msg/StringVec",
         header("strings") + ' data: ["first", "b::c", "", "ünïcode"]', check_string_v),
    Case("float_v", "ignition.msgs.Float_V", "ros_gz_interfaces/msg/Float32Array",
         header("ignored") + " data: [1.5, -2.25, 1024, 0.1]", check_float_v),
    Case("logical_camera", "ignition.msgs.LogicalCameraImage",
         "ros_gz_interfaces/msg/LogicalCameraImage", LOGICAL_CAMERA_TEXT, check_logical_camera),
    Case("log_playback", "ignition.msgs.LogPlaybackStatistics",
         "ros_gz_interfaces/msg/LogPlaybackStatistics",
         header("log") + " start_time { sec: 1700000000 nsec: 5 }"
         " end_time { sec: 1700000360 nsec: 999999999 }", check_log_playback),
    Case("detection_2d", "ignition.msgs.AnnotatedAxisAligned2DBox",
         "vision_msgs/msg/Detection2D",
         header("camera") + " box { min_corner { x: 2 y: 2 } max_corner { x: 4 y: 6 } }"
         " label: 42", check_detection_2d),
    Case("gps_fix", "ignition.msgs.NavSat", "gps_msgs/msg/GPSFix",
         header("overwritten") + " latitude_deg: -33.8688 longitude_deg: 151.2093"
         ' altitude: 58.25 velocity_east: 3 velocity_north: 4 velocity_up: -0.5'
         ' frame_id: "gps::antenna"', check_gps_fix),
    Case("actuators", "ignition.msgs.Actuators", "actuator_msgs/msg/Actuators",
         header("base") + " position: [0.5, -0.5] velocity: [100.25, 200.5, -300.75]"
         " normalized: [0.125]", check_actuators),
    Case("joint_trajectory", "ignition.msgs.JointTrajectory",
         "trajectory_msgs/msg/JointTrajectory",
         header("arm_base") + ' joint_names: ["joint_1", "joint_2"]'
         " points { positions: [0.5, 1.5] accelerations: [0.25] effort: [4, 5]"
         " time_from_start { sec: 3 nsec: 1250000000 } }"
         " points { positions: [-0.5, -1.5] time_from_start { sec: 2 nsec: -250000000 } }",
         check_joint_trajectory),
    Case("any", "ignition.msgs.Any", "rcl_interfaces/msg/ParameterValue",
         "type: DOUBLE double_value: 2.718281828", check_any),
)  # fmt: skip
