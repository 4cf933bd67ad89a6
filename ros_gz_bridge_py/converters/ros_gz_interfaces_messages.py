"""Converters for the ros_gz_interfaces messages (conversions.md §3.13).

The pair table and the services live in ``ros_gz_interfaces``; this module holds the
conversions, both directions side by side, and the fill helpers the services reuse.

Differences from ros_gz_bridge:
- Contact R→G fills gz ``collision2`` from ROS ``collision2``; the reference copies
  ``collision1`` into both (upstream bug).
- ParamVec G→R lists a Param's map entries sorted by key; the reference order is the C++
  protobuf map iteration order, which is unspecified.
- Unknown enum values (Entity type, MaterialColor entity_match) fall back to 0 like the
  reference, but without printing an error; so does an unparsable Dataframe ``rssi`` entry,
  which keeps the previous value.
- WorldStatistics and LogPlaybackStatistics are converted field by field by name (times
  copied as in §1.2), as ros_gz PR #841 describes them; its converter code was not available
  to compare with. R→G always sends every Time submessage, even a zero one.
"""

from __future__ import annotations

import math
import re
import sys
from array import array
from typing import Any

import numpy as np
from geometry_msgs.msg import Vector3
from rcl_interfaces.msg import Parameter
from ros_gz_interfaces.msg import (
    Altimeter,
    Contact,
    Contacts,
    Dataframe,
    Entity,
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
    WorldStatistics,
)

from ros_gz_bridge_py.converters.builtin_interfaces import fill_gz_time, fill_ros_time
from ros_gz_bridge_py.converters.geometry_msgs import (
    fill_gz_pose,
    fill_gz_vector3,
    fill_gz_wrench,
    fill_ros_pose,
    fill_ros_vector3,
    fill_ros_wrench,
)
from ros_gz_bridge_py.converters.rcl_interfaces import fill_gz_any, fill_ros_parameter_value
from ros_gz_bridge_py.converters.std_msgs import (
    add_gz_header_entry,
    fill_gz_header,
    fill_ros_header,
)
from ros_gz_bridge_py.msgs import message_class

_GzAltimeter = message_class("gz.msgs.Altimeter")
_GzContact = message_class("gz.msgs.Contact")
_GzContacts = message_class("gz.msgs.Contacts")
_GzDataframe = message_class("gz.msgs.Dataframe")
_GzEntity = message_class("gz.msgs.Entity")
_GzEntityWrench = message_class("gz.msgs.EntityWrench")
_GzFloatV = message_class("gz.msgs.Float_V")
_GzGuiCamera = message_class("gz.msgs.GUICamera")
_GzJointWrench = message_class("gz.msgs.JointWrench")
_GzLight = message_class("gz.msgs.Light")
_GzLogPlaybackStatistics = message_class("gz.msgs.LogPlaybackStatistics")
_GzMaterialColor = message_class("gz.msgs.MaterialColor")
_GzParam = message_class("gz.msgs.Param")
_GzParamV = message_class("gz.msgs.Param_V")
_GzSensorNoise = message_class("gz.msgs.SensorNoise")
_GzStringMsgV = message_class("gz.msgs.StringMsg_V")
_GzTrackVisual = message_class("gz.msgs.TrackVisual")
_GzVideoRecord = message_class("gz.msgs.VideoRecord")
_GzWorldStatistics = message_class("gz.msgs.WorldStatistics")

#: Entity types with the same number on both sides (NONE..JOINT); gz ACTOR/WORLD have no ROS twin.
_ENTITY_TYPES = range(8)
_LIGHT_TYPES = (0, 1, 2)
_ENTITY_MATCHES = (0, 1)
_NOISE_TYPES = (0, 2, 3)

RSSI_KEY = "rssi"


def _known_or_zero(value: int, known: range | tuple[int, ...]) -> int:
    """``value`` if both sides define it, else the 0 the reference falls back to."""
    return value if value in known else 0


def _fill_gz_color(ros: Any, gz: Any) -> None:
    gz.r = ros.r
    gz.g = ros.g
    gz.b = ros.b
    gz.a = ros.a


def _fill_ros_color(gz: Any, ros: Any) -> None:
    ros.r = gz.r
    ros.g = gz.g
    ros.b = gz.b
    ros.a = gz.a


def _ros_vector3(gz: Any) -> Any:
    ros = Vector3()
    fill_ros_vector3(gz, ros)
    return ros


# --- Entity ---------------------------------------------------------------------------------


def fill_gz_entity(ros: Any, gz: Any) -> None:
    """id, name and type (unknown types become NONE); gz header stays unset."""
    gz.id = ros.id
    gz.name = ros.name
    gz.type = _known_or_zero(ros.type, _ENTITY_TYPES)


def fill_ros_entity(gz: Any, ros: Any) -> None:
    """id, name and type; gz ACTOR, WORLD and unknown types become NONE."""
    ros.id = gz.id
    ros.name = gz.name
    ros.type = _known_or_zero(gz.type, _ENTITY_TYPES)


def entity_to_gz(ros: Any) -> Any:
    gz = _GzEntity()
    fill_gz_entity(ros, gz)
    return gz


def entity_to_ros(gz: Any) -> Any:
    ros = Entity()
    fill_ros_entity(gz, ros)
    return ros


# --- EntityWrench ---------------------------------------------------------------------------


def entity_wrench_to_gz(ros: Any) -> Any:
    gz = _GzEntityWrench()
    fill_gz_header(ros.header, gz.header)
    fill_gz_entity(ros.entity, gz.entity)
    fill_gz_wrench(ros.wrench, gz.wrench)
    return gz


def entity_wrench_to_ros(gz: Any) -> Any:
    ros = EntityWrench()
    fill_ros_header(gz.header, ros.header)
    fill_ros_entity(gz.entity, ros.entity)
    fill_ros_wrench(gz.wrench, ros.wrench)
    return ros


# --- JointWrench ----------------------------------------------------------------------------


def fill_gz_joint_wrench(ros: Any, gz: Any) -> None:
    fill_gz_header(ros.header, gz.header)
    gz.body_1_name = ros.body_1_name.data
    gz.body_1_id = ros.body_1_id.data
    gz.body_2_name = ros.body_2_name.data
    gz.body_2_id = ros.body_2_id.data
    fill_gz_wrench(ros.body_1_wrench, gz.body_1_wrench)
    fill_gz_wrench(ros.body_2_wrench, gz.body_2_wrench)


def fill_ros_joint_wrench(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.body_1_name.data = gz.body_1_name
    ros.body_1_id.data = gz.body_1_id
    ros.body_2_name.data = gz.body_2_name
    ros.body_2_id.data = gz.body_2_id
    fill_ros_wrench(gz.body_1_wrench, ros.body_1_wrench)
    fill_ros_wrench(gz.body_2_wrench, ros.body_2_wrench)


def joint_wrench_to_gz(ros: Any) -> Any:
    gz = _GzJointWrench()
    fill_gz_joint_wrench(ros, gz)
    return gz


def joint_wrench_to_ros(gz: Any) -> Any:
    ros = JointWrench()
    fill_ros_joint_wrench(gz, ros)
    return ros


# --- Contact, Contacts ----------------------------------------------------------------------


def fill_gz_contact(ros: Any, gz: Any) -> None:
    """Everything but gz ``header`` and ``world``, which stay unset."""
    fill_gz_entity(ros.collision1, gz.collision1)
    fill_gz_entity(ros.collision2, gz.collision2)
    for position in ros.positions:
        fill_gz_vector3(position, gz.position.add())
    for normal in ros.normals:
        fill_gz_vector3(normal, gz.normal.add())
    gz.depth.extend(ros.depths)
    for wrench in ros.wrenches:
        fill_gz_joint_wrench(wrench, gz.wrench.add())


def fill_ros_contact(gz: Any, ros: Any) -> None:
    fill_ros_entity(gz.collision1, ros.collision1)
    fill_ros_entity(gz.collision2, ros.collision2)
    ros.positions = [_ros_vector3(v) for v in gz.position]
    ros.normals = [_ros_vector3(v) for v in gz.normal]
    ros.depths = array("d", gz.depth)
    ros.wrenches = [joint_wrench_to_ros(w) for w in gz.wrench]


def contact_to_gz(ros: Any) -> Any:
    gz = _GzContact()
    fill_gz_contact(ros, gz)
    return gz


def contact_to_ros(gz: Any) -> Any:
    ros = Contact()
    fill_ros_contact(gz, ros)
    return ros


def contacts_to_gz(ros: Any) -> Any:
    gz = _GzContacts()
    fill_gz_header(ros.header, gz.header)
    for contact in ros.contacts:
        fill_gz_contact(contact, gz.contact.add())
    return gz


def contacts_to_ros(gz: Any) -> Any:
    ros = Contacts()
    fill_ros_header(gz.header, ros.header)
    ros.contacts = [contact_to_ros(contact) for contact in gz.contact]
    return ros


# --- Altimeter ------------------------------------------------------------------------------


def altimeter_to_gz(ros: Any) -> Any:
    gz = _GzAltimeter()
    fill_gz_header(ros.header, gz.header)
    gz.vertical_position = ros.vertical_position
    gz.vertical_velocity = ros.vertical_velocity
    gz.vertical_reference = ros.vertical_reference
    return gz


def altimeter_to_ros(gz: Any) -> Any:
    ros = Altimeter()
    fill_ros_header(gz.header, ros.header)
    ros.vertical_position = gz.vertical_position
    ros.vertical_velocity = gz.vertical_velocity
    ros.vertical_reference = gz.vertical_reference
    return ros


# --- Dataframe ------------------------------------------------------------------------------

# The longest prefix C strtod accepts: C-locale whitespace, a sign, then a hex float, a decimal
# float, inf/infinity or nan/nan(chars). Hex comes first so "0x1" is not read as "0".
_STRTOD_PREFIX = re.compile(
    r"""[ \t\n\v\f\r]*
    (?P<number>[+-]?(?:
        (?P<hex>0[xX](?P<hex_digits>[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)
            (?:[pP][+-]?[0-9]+)?)
      | (?P<dec>(?P<dec_digits>[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)
      | [iI][nN][fF](?:[iI][nN][iI][tT][yY])?
      | (?P<nan>[nN][aA][nN])(?:\([0-9A-Za-z_]*\))?
    ))""",
    re.VERBOSE,
)


def parse_strtod(text: str) -> float | None:
    """The value C ``std::stod`` reads from ``text``, or None where it throws.

    None means no number at the start (invalid_argument) or a finite number too large or too
    small for a normal double (out_of_range, glibc's ERANGE).
    """
    match = _STRTOD_PREFIX.match(text)
    if match is None:
        return None
    number = match.group("number")
    if match.group("nan") is not None:
        return -math.nan if number.startswith("-") else math.nan
    if match.group("hex") is not None:
        try:
            value = float.fromhex(number)
        except OverflowError:
            return None
        digits = match.group("hex_digits")
    elif match.group("dec") is not None:
        value = float(number)
        if math.isinf(value):
            return None
        digits = match.group("dec_digits")
    else:
        return float(number.lower().replace("infinity", "inf"))
    nonzero = any(c not in "0." for c in digits)
    if nonzero and abs(value) < sys.float_info.min:
        return None
    return value


def dataframe_to_gz(ros: Any) -> Any:
    """The rssi travels as a ``"%f"`` string in a header entry after ``frame_id``."""
    gz = _GzDataframe()
    fill_gz_header(ros.header, gz.header)
    add_gz_header_entry(gz.header, RSSI_KEY, f"{ros.rssi:f}")
    gz.src_address = ros.src_address
    gz.dst_address = ros.dst_address
    gz.data = bytes(ros.data)
    return gz


def dataframe_to_ros(gz: Any) -> Any:
    """The last parsable ``rssi`` header entry wins; unparsable ones are skipped."""
    ros = Dataframe()
    fill_ros_header(gz.header, ros.header)
    ros.src_address = gz.src_address
    ros.dst_address = gz.dst_address
    for entry in gz.header.data:
        if entry.key == RSSI_KEY and entry.value:
            rssi = parse_strtod(entry.value[0])
            if rssi is not None:
                ros.rssi = rssi
    ros.data = gz.data
    return ros


# --- Float32Array, StringVec ----------------------------------------------------------------


def float32_array_to_gz(ros: Any) -> Any:
    """No header on either side."""
    gz = _GzFloatV()
    gz.data.extend(ros.data)
    return gz


def float32_array_to_ros(gz: Any) -> Any:
    ros = Float32Array()
    # numpy reads the repeated field as one buffer: ~300x faster than iterating it.
    ros.data = array("f", np.asarray(gz.data, dtype=np.float32).tobytes())
    return ros


def string_vec_to_gz(ros: Any) -> Any:
    gz = _GzStringMsgV()
    fill_gz_header(ros.header, gz.header)
    gz.data.extend(ros.data)
    return gz


def string_vec_to_ros(gz: Any) -> Any:
    ros = StringVec()
    fill_ros_header(gz.header, ros.header)
    ros.data = list(gz.data)
    return ros


# --- TrackVisual, GuiCamera -----------------------------------------------------------------


def fill_gz_track_visual(ros: Any, gz: Any) -> None:
    fill_gz_header(ros.header, gz.header)
    gz.name = ros.name
    gz.id = ros.id
    gz.inherit_orientation = ros.inherit_orientation
    gz.min_dist = ros.min_dist
    gz.max_dist = ros.max_dist
    gz.static = ros.is_static
    gz.use_model_frame = ros.use_model_frame
    fill_gz_vector3(ros.xyz, gz.xyz)
    gz.inherit_yaw = ros.inherit_yaw


def fill_ros_track_visual(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.name = gz.name
    ros.id = gz.id
    ros.inherit_orientation = gz.inherit_orientation
    ros.min_dist = gz.min_dist
    ros.max_dist = gz.max_dist
    ros.is_static = gz.static
    ros.use_model_frame = gz.use_model_frame
    fill_ros_vector3(gz.xyz, ros.xyz)
    ros.inherit_yaw = gz.inherit_yaw


def track_visual_to_gz(ros: Any) -> Any:
    gz = _GzTrackVisual()
    fill_gz_track_visual(ros, gz)
    return gz


def track_visual_to_ros(gz: Any) -> Any:
    ros = TrackVisual()
    fill_ros_track_visual(gz, ros)
    return ros


def gui_camera_to_gz(ros: Any) -> Any:
    gz = _GzGuiCamera()
    fill_gz_header(ros.header, gz.header)
    gz.name = ros.name
    gz.view_controller = ros.view_controller
    fill_gz_pose(ros.pose, gz.pose)
    fill_gz_track_visual(ros.track, gz.track)
    gz.projection_type = ros.projection_type
    return gz


def gui_camera_to_ros(gz: Any) -> Any:
    ros = GuiCamera()
    fill_ros_header(gz.header, ros.header)
    ros.name = gz.name
    ros.view_controller = gz.view_controller
    fill_ros_pose(gz.pose, ros.pose)
    fill_ros_track_visual(gz.track, ros.track)
    ros.projection_type = gz.projection_type
    return ros


# --- Light ----------------------------------------------------------------------------------


def light_to_gz(ros: Any) -> Any:
    """gz ``is_light_off`` and ``visualize_visual`` have no ROS field and stay false."""
    gz = _GzLight()
    fill_gz_header(ros.header, gz.header)
    gz.name = ros.name
    gz.type = _known_or_zero(ros.type, _LIGHT_TYPES)
    fill_gz_pose(ros.pose, gz.pose)
    _fill_gz_color(ros.diffuse, gz.diffuse)
    _fill_gz_color(ros.specular, gz.specular)
    gz.attenuation_constant = ros.attenuation_constant
    gz.attenuation_linear = ros.attenuation_linear
    gz.attenuation_quadratic = ros.attenuation_quadratic
    fill_gz_vector3(ros.direction, gz.direction)
    gz.range = ros.range
    gz.cast_shadows = ros.cast_shadows
    gz.spot_inner_angle = ros.spot_inner_angle
    gz.spot_outer_angle = ros.spot_outer_angle
    gz.spot_falloff = ros.spot_falloff
    gz.id = ros.id
    gz.parent_id = ros.parent_id
    gz.intensity = ros.intensity
    return gz


def light_to_ros(gz: Any) -> Any:
    ros = Light()
    fill_ros_header(gz.header, ros.header)
    ros.name = gz.name
    ros.type = _known_or_zero(gz.type, _LIGHT_TYPES)
    fill_ros_pose(gz.pose, ros.pose)
    _fill_ros_color(gz.diffuse, ros.diffuse)
    _fill_ros_color(gz.specular, ros.specular)
    ros.attenuation_constant = gz.attenuation_constant
    ros.attenuation_linear = gz.attenuation_linear
    ros.attenuation_quadratic = gz.attenuation_quadratic
    fill_ros_vector3(gz.direction, ros.direction)
    ros.range = gz.range
    ros.cast_shadows = gz.cast_shadows
    ros.spot_inner_angle = gz.spot_inner_angle
    ros.spot_outer_angle = gz.spot_outer_angle
    ros.spot_falloff = gz.spot_falloff
    ros.id = gz.id
    ros.parent_id = gz.parent_id
    ros.intensity = gz.intensity
    return ros


# --- MaterialColor --------------------------------------------------------------------------


def material_color_to_gz(ros: Any) -> Any:
    gz = _GzMaterialColor()
    fill_gz_header(ros.header, gz.header)
    fill_gz_entity(ros.entity, gz.entity)
    _fill_gz_color(ros.ambient, gz.ambient)
    _fill_gz_color(ros.diffuse, gz.diffuse)
    _fill_gz_color(ros.specular, gz.specular)
    _fill_gz_color(ros.emissive, gz.emissive)
    gz.shininess = ros.shininess
    gz.entity_match = _known_or_zero(ros.entity_match, _ENTITY_MATCHES)
    return gz


def material_color_to_ros(gz: Any) -> Any:
    ros = MaterialColor()
    fill_ros_header(gz.header, ros.header)
    fill_ros_entity(gz.entity, ros.entity)
    _fill_ros_color(gz.ambient, ros.ambient)
    _fill_ros_color(gz.diffuse, ros.diffuse)
    _fill_ros_color(gz.specular, ros.specular)
    _fill_ros_color(gz.emissive, ros.emissive)
    ros.shininess = gz.shininess
    ros.entity_match = _known_or_zero(gz.entity_match, _ENTITY_MATCHES)
    return ros


# --- SensorNoise, VideoRecord ---------------------------------------------------------------


def sensor_noise_to_gz(ros: Any) -> Any:
    """``dynamic_bias_correlation_time`` is not converted (reference behaviour)."""
    gz = _GzSensorNoise()
    fill_gz_header(ros.header, gz.header)
    gz.type = _known_or_zero(ros.type, _NOISE_TYPES)
    gz.mean = ros.mean
    gz.stddev = ros.stddev
    gz.bias_mean = ros.bias_mean
    gz.bias_stddev = ros.bias_stddev
    gz.precision = ros.precision
    gz.dynamic_bias_stddev = ros.dynamic_bias_stddev
    return gz


def sensor_noise_to_ros(gz: Any) -> Any:
    ros = SensorNoise()
    fill_ros_header(gz.header, ros.header)
    ros.type = _known_or_zero(gz.type, _NOISE_TYPES)
    ros.mean = gz.mean
    ros.stddev = gz.stddev
    ros.bias_mean = gz.bias_mean
    ros.bias_stddev = gz.bias_stddev
    ros.precision = gz.precision
    ros.dynamic_bias_stddev = gz.dynamic_bias_stddev
    return ros


def video_record_to_gz(ros: Any) -> Any:
    gz = _GzVideoRecord()
    fill_gz_header(ros.header, gz.header)
    gz.start = ros.start
    gz.stop = ros.stop
    gz.format = ros.format
    gz.save_filename = ros.save_filename
    return gz


def video_record_to_ros(gz: Any) -> Any:
    ros = VideoRecord()
    fill_ros_header(gz.header, ros.header)
    ros.start = gz.start
    ros.stop = gz.stop
    ros.format = gz.format
    ros.save_filename = gz.save_filename
    return ros


# --- ParamVec <-> Param, Param_V ------------------------------------------------------------


def _fill_gz_param(ros: Any, gz: Any) -> None:
    """Header and one map entry per parameter; a repeated name overwrites the earlier one."""
    fill_gz_header(ros.header, gz.header)
    for parameter in ros.params:
        value = gz.params[parameter.name]
        value.Clear()
        fill_gz_any(parameter.value, value)


def _ros_parameters(gz_param: Any) -> list[Any]:
    """Map entries sorted by key, then each child's parameters prefixed ``child_<i>/``."""
    parameters = []
    for name in sorted(gz_param.params):
        parameter = Parameter(name=name)
        fill_ros_parameter_value(gz_param.params[name], parameter.value)
        parameters.append(parameter)
    for index, child in enumerate(gz_param.children):
        parameters.extend(_prefixed(f"child_{index}/", _ros_parameters(child)))
    return parameters


def _prefixed(prefix: str, parameters: list[Any]) -> list[Any]:
    for parameter in parameters:
        parameter.name = prefix + parameter.name
    return parameters


def param_vec_to_gz_param(ros: Any) -> Any:
    gz = _GzParam()
    _fill_gz_param(ros, gz)
    return gz


def param_vec_from_gz_param(gz: Any) -> Any:
    ros = ParamVec()
    fill_ros_header(gz.header, ros.header)
    ros.params = _ros_parameters(gz)
    return ros


def param_vec_to_gz_param_v(ros: Any) -> Any:
    """Everything goes into ``param[0]``, which carries its own copy of the header."""
    gz = _GzParamV()
    fill_gz_header(ros.header, gz.header)
    _fill_gz_param(ros, gz.param.add())
    return gz


def param_vec_from_gz_param_v(gz: Any) -> Any:
    """Each ``param[p]`` flattened with its names prefixed ``param_<p>/``."""
    ros = ParamVec()
    fill_ros_header(gz.header, ros.header)
    parameters = []
    for index, param in enumerate(gz.param):
        parameters.extend(_prefixed(f"param_{index}/", _ros_parameters(param)))
    ros.params = parameters
    return ros


# --- LogPlaybackStatistics, WorldStatistics -------------------------------------------------


def _fill_gz_present_time(ros_time: Any, gz_time: Any) -> None:
    """A gz Time that is serialized even when it is zero."""
    gz_time.SetInParent()
    fill_gz_time(ros_time, gz_time)


def fill_gz_log_playback_stats(ros: Any, gz: Any) -> None:
    """Header, start_time and end_time; all three submessages are present."""
    fill_gz_header(ros.header, gz.header)
    _fill_gz_present_time(ros.start_time, gz.start_time)
    _fill_gz_present_time(ros.end_time, gz.end_time)


def fill_ros_log_playback_stats(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    fill_ros_time(gz.start_time, ros.start_time)
    fill_ros_time(gz.end_time, ros.end_time)


def log_playback_statistics_to_gz(ros: Any) -> Any:
    gz = _GzLogPlaybackStatistics()
    fill_gz_log_playback_stats(ros, gz)
    return gz


def log_playback_statistics_to_ros(gz: Any) -> Any:
    ros = LogPlaybackStatistics()
    fill_ros_log_playback_stats(gz, ros)
    return ros


_STATS_TIMES = ("sim_time", "pause_time", "real_time", "step_size")


def world_statistics_to_gz(ros: Any) -> Any:
    """Every submessage is present; ``log_playback_statistics`` is gz ``log_playback_stats``."""
    gz = _GzWorldStatistics()
    fill_gz_header(ros.header, gz.header)
    for name in _STATS_TIMES:
        _fill_gz_present_time(getattr(ros, name), getattr(gz, name))
    gz.paused = ros.paused
    gz.iterations = ros.iterations
    gz.model_count = ros.model_count
    fill_gz_log_playback_stats(ros.log_playback_statistics, gz.log_playback_stats)
    gz.real_time_factor = ros.real_time_factor
    gz.stepping = ros.stepping
    return gz


def world_statistics_to_ros(gz: Any) -> Any:
    ros = WorldStatistics()
    fill_ros_header(gz.header, ros.header)
    for name in _STATS_TIMES:
        fill_ros_time(getattr(gz, name), getattr(ros, name))
    ros.paused = gz.paused
    ros.iterations = gz.iterations
    ros.model_count = gz.model_count
    fill_ros_log_playback_stats(gz.log_playback_stats, ros.log_playback_statistics)
    ros.real_time_factor = gz.real_time_factor
    ros.stepping = gz.stepping
    return ros
