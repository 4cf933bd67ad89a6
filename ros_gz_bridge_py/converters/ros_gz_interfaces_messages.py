"""Converters for the ros_gz_interfaces messages (docs/conversions-per-package.md §3.13).

The pair table and the services live in ``ros_gz_interfaces``; this module holds the
conversions, each declared once for both directions where it is a list of fields, and the
fills the services reuse.

Differences from ros_gz_bridge:
- Contact R→G fills gz ``collision2`` from ROS ``collision2``; the reference copies
  ``collision1`` into both (upstream bug).
- ParamVec G→R lists a Param's map entries sorted by key; the reference order is the C++
  protobuf map iteration order, which is unspecified.
- Unknown enum values (Entity type, MaterialColor entity_match) fall back to 0 like the
  reference, but without printing an error; so does an unparsable Dataframe ``rssi`` entry,
  which keeps the previous value.
- WorldStatistics and LogPlaybackStatistics are converted field by field by name (times
  copied as in docs/conversions.md §1.2), as ros_gz PR #841 describes them; its converter code was
  not available to compare with. R→G always sends every Time submessage, even a zero one.
"""

from __future__ import annotations

import math
import re
import sys
from typing import Any

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

from ros_gz_bridge_py.converters._fields import STRINGS, Value, converters, each, fields, numbers
from ros_gz_bridge_py.converters.builtin_interfaces import PRESENT_TIME
from ros_gz_bridge_py.converters.geometry_msgs import POSE, VECTOR3, WRENCH
from ros_gz_bridge_py.converters.rcl_interfaces import fill_gz_any, fill_ros_parameter_value
from ros_gz_bridge_py.converters.std_msgs import COLOR, HEADER, add_gz_header_entry
from ros_gz_bridge_py.msgs import message_class

_GzDataframe = message_class("gz.msgs.Dataframe")
_GzParam = message_class("gz.msgs.Param")
_GzParamV = message_class("gz.msgs.Param_V")

RSSI_KEY = "rssi"


def _known(values: range | tuple[int, ...]) -> Value:
    """An enum value both sides define as it is, else the 0 the reference falls back to."""

    def convert(value: int) -> int:
        return value if value in values else 0

    return Value(convert, convert)


# --- Entity, EntityWrench, JointWrench --------------------------------------------------------

#: id, name and type; gz header stays unset. Entity types with the same number on both sides
#: (NONE..JOINT); gz ACTOR, WORLD and unknown types become NONE.
ENTITY = fields("id", "name", ("type", _known(range(8))))
entity_to_gz, entity_to_ros = converters(ENTITY, Entity, "gz.msgs.Entity")

entity_wrench_to_gz, entity_wrench_to_ros = converters(
    fields(("header", HEADER), ("entity", ENTITY), ("wrench", WRENCH)),
    EntityWrench,
    "gz.msgs.EntityWrench",
)

JOINT_WRENCH = fields(
    ("header", HEADER),
    ("body_1_name.data", "body_1_name"),
    ("body_1_id.data", "body_1_id"),
    ("body_2_name.data", "body_2_name"),
    ("body_2_id.data", "body_2_id"),
    ("body_1_wrench", WRENCH),
    ("body_2_wrench", WRENCH),
)
joint_wrench_to_gz, joint_wrench_to_ros = converters(
    JOINT_WRENCH, JointWrench, "gz.msgs.JointWrench"
)


# --- Contact, Contacts ----------------------------------------------------------------------


#: Everything but gz ``header`` and ``world``, which stay unset.
CONTACT = fields(
    ("collision1", ENTITY),
    ("collision2", ENTITY),
    ("positions", "position", each(VECTOR3, Vector3)),
    ("normals", "normal", each(VECTOR3, Vector3)),
    ("depths", "depth", numbers("d")),
    ("wrenches", "wrench", each(JOINT_WRENCH, JointWrench)),
)
contact_to_gz, contact_to_ros = converters(CONTACT, Contact, "gz.msgs.Contact")
contacts_to_gz, contacts_to_ros = converters(
    fields(("header", HEADER), ("contacts", "contact", each(CONTACT, Contact))),
    Contacts,
    "gz.msgs.Contacts",
)


# --- Altimeter ------------------------------------------------------------------------------

altimeter_to_gz, altimeter_to_ros = converters(
    fields(("header", HEADER), "vertical_position", "vertical_velocity", "vertical_reference"),
    Altimeter,
    "gz.msgs.Altimeter",
)


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
    HEADER.to_gz(ros.header, gz.header)
    add_gz_header_entry(gz.header, RSSI_KEY, f"{ros.rssi:f}")
    gz.src_address = ros.src_address
    gz.dst_address = ros.dst_address
    gz.data = bytes(ros.data)
    return gz


def dataframe_to_ros(gz: Any) -> Any:
    """The last parsable ``rssi`` header entry wins; unparsable ones are skipped."""
    ros = Dataframe()
    HEADER.to_ros(gz.header, ros.header)
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


#: No header on either side.
float32_array_to_gz, float32_array_to_ros = converters(
    fields(("data", numbers("f"))), Float32Array, "gz.msgs.Float_V"
)
string_vec_to_gz, string_vec_to_ros = converters(
    fields(("header", HEADER), ("data", STRINGS)), StringVec, "gz.msgs.StringMsg_V"
)


# --- TrackVisual, GuiCamera -----------------------------------------------------------------

TRACK_VISUAL = fields(
    ("header", HEADER),
    "name",
    "id",
    "inherit_orientation",
    "min_dist",
    "max_dist",
    ("is_static", "static"),
    "use_model_frame",
    ("xyz", VECTOR3),
    "inherit_yaw",
)
track_visual_to_gz, track_visual_to_ros = converters(
    TRACK_VISUAL, TrackVisual, "gz.msgs.TrackVisual"
)

gui_camera_to_gz, gui_camera_to_ros = converters(
    fields(
        ("header", HEADER),
        "name",
        "view_controller",
        ("pose", POSE),
        ("track", TRACK_VISUAL),
        "projection_type",
    ),
    GuiCamera,
    "gz.msgs.GUICamera",
)


# --- Light, MaterialColor -------------------------------------------------------------------

#: gz ``is_light_off`` and ``visualize_visual`` have no ROS field and stay false.
light_to_gz, light_to_ros = converters(
    fields(
        ("header", HEADER),
        "name",
        ("type", _known((0, 1, 2))),
        ("pose", POSE),
        ("diffuse", COLOR),
        ("specular", COLOR),
        "attenuation_constant",
        "attenuation_linear",
        "attenuation_quadratic",
        ("direction", VECTOR3),
        "range",
        "cast_shadows",
        "spot_inner_angle",
        "spot_outer_angle",
        "spot_falloff",
        "id",
        "parent_id",
        "intensity",
    ),
    Light,
    "gz.msgs.Light",
)

material_color_to_gz, material_color_to_ros = converters(
    fields(
        ("header", HEADER),
        ("entity", ENTITY),
        ("ambient", COLOR),
        ("diffuse", COLOR),
        ("specular", COLOR),
        ("emissive", COLOR),
        "shininess",
        ("entity_match", _known((0, 1))),
    ),
    MaterialColor,
    "gz.msgs.MaterialColor",
)


# --- SensorNoise, VideoRecord ---------------------------------------------------------------

#: ``dynamic_bias_correlation_time`` is not converted (reference behaviour).
sensor_noise_to_gz, sensor_noise_to_ros = converters(
    fields(
        ("header", HEADER),
        ("type", _known((0, 2, 3))),
        "mean",
        "stddev",
        "bias_mean",
        "bias_stddev",
        "precision",
        "dynamic_bias_stddev",
    ),
    SensorNoise,
    "gz.msgs.SensorNoise",
)

video_record_to_gz, video_record_to_ros = converters(
    fields(("header", HEADER), "start", "stop", "format", "save_filename"),
    VideoRecord,
    "gz.msgs.VideoRecord",
)


# --- ParamVec <-> Param, Param_V ------------------------------------------------------------


def _fill_gz_param(ros: Any, gz: Any) -> None:
    """Header and one map entry per parameter; a repeated name overwrites the earlier one."""
    HEADER.to_gz(ros.header, gz.header)
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
    HEADER.to_ros(gz.header, ros.header)
    ros.params = _ros_parameters(gz)
    return ros


def param_vec_to_gz_param_v(ros: Any) -> Any:
    """Everything goes into ``param[0]``, which carries its own copy of the header."""
    gz = _GzParamV()
    HEADER.to_gz(ros.header, gz.header)
    _fill_gz_param(ros, gz.param.add())
    return gz


def param_vec_from_gz_param_v(gz: Any) -> Any:
    """Each ``param[p]`` flattened with its names prefixed ``param_<p>/``."""
    ros = ParamVec()
    HEADER.to_ros(gz.header, ros.header)
    parameters = []
    for index, param in enumerate(gz.param):
        parameters.extend(_prefixed(f"param_{index}/", _ros_parameters(param)))
    ros.params = parameters
    return ros


# --- LogPlaybackStatistics, WorldStatistics -------------------------------------------------

#: Header, start_time and end_time; R→G all three submessages are present.
LOG_PLAYBACK_STATISTICS = fields(
    ("header", HEADER), ("start_time", PRESENT_TIME), ("end_time", PRESENT_TIME)
)
log_playback_statistics_to_gz, log_playback_statistics_to_ros = converters(
    LOG_PLAYBACK_STATISTICS, LogPlaybackStatistics, "gz.msgs.LogPlaybackStatistics"
)

#: R→G every submessage is present; ``log_playback_statistics`` is gz ``log_playback_stats``.
world_statistics_to_gz, world_statistics_to_ros = converters(
    fields(
        ("header", HEADER),
        ("sim_time", PRESENT_TIME),
        ("pause_time", PRESENT_TIME),
        ("real_time", PRESENT_TIME),
        ("step_size", PRESENT_TIME),
        "paused",
        "iterations",
        "model_count",
        ("log_playback_statistics", "log_playback_stats", LOG_PLAYBACK_STATISTICS),
        "real_time_factor",
        "stepping",
    ),
    WorldStatistics,
    "gz.msgs.WorldStatistics",
)
