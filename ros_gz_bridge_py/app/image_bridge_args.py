"""What ``image_bridge`` is asked to bridge, worked out without rclpy: pure functions on strings.

Topic arguments become Gazebo->ROS ``sensor_msgs/msg/Image`` <-> Gazebo Image
:class:`TopicBridgeSpec` values; :mod:`ros_gz_bridge_py.app.image_bridge` hands them to a
:class:`~ros_gz_bridge_py.core.bridge.Bridge`. Also here: the ``qos`` and ``gz_type``
parameter values, the camera_info topic beside an image topic, and which entries of a
``config_file`` apply.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from ros_gz_bridge_py.config import (
    BridgeSpec,
    Direction,
    ParseResult,
    TopicBridgeSpec,
    UsageError,
)
from ros_gz_bridge_py.errors import ConfigError

IMAGE_ROS_TYPE = "sensor_msgs/msg/Image"
CAMERA_INFO_ROS_TYPE = "sensor_msgs/msg/CameraInfo"
#: ``gz_type`` values: the two spellings of one message, each taking publishers of both
#: (Harmonic and newer publish ``gz.msgs.Image``, Fortress ``ignition.msgs.Image``).
GZ_IMAGE_TYPES = ("gz.msgs.Image", "ignition.msgs.Image")
RENAME = ":="
ROS_ARGS_START = "--ros-args"
ROS_ARGS_END = "--"
#: gz-sensors' camera publishes its ``gz.msgs.CameraInfo`` on the image topic with the last
#: token replaced by this (``/a/b/image`` -> ``/a/b/camera_info``).
CAMERA_INFO_NAME = "camera_info"

#: ``qos`` parameter value -> ``qos_profile`` name (None: reliable, volatile, keep-last 10).
QOS_CHOICES: dict[str, str | None] = {
    "default": None,
    "sensor_data": "SENSOR_DATA",
    "system_default": "SYSTEM_DEFAULT",
}

USAGE = """\
Bridge a collection of Gazebo Transport image topics to ROS.

usage: image_bridge TOPIC [TOPIC ...] [--ros-args -p NAME:=VALUE ...]

  TOPIC                   Gazebo image topic, published under the same name in ROS (relative
                          names resolve in the node namespace)
  GZ_TOPIC:=ROS_TOPIC     Gazebo image topic GZ_TOPIC, published in ROS as ROS_TOPIC

Parameters (--ros-args -p NAME:=VALUE):
  qos:=default|sensor_data|system_default   ROS publisher QoS (default: reliable, keep-last 10)
  camera_info:=true       also bridge the camera's <topic dir>/camera_info as CameraInfo
  config_file:=FILE       parameter_bridge YAML; its Image and CameraInfo entries are bridged
  lazy:=true              subscribe to Gazebo only while ROS has subscribers
  expand_gz_topic_names:=true   relative Gazebo names get the node namespace (-r __ns:=/robot1)
  max_rate:=HZ            pass at most HZ images per second per topic (the rest is dropped)
  status_period:=S        publish each topic's status on /diagnostics every S seconds
  subscription_heartbeat:=MS   how often lazy bridges check for subscribers (default 1000)
  gz_type:=TYPE           the Gazebo type (default gz.msgs.Image; either spelling takes the
                          publishers of every Gazebo line, Fortress's ignition.msgs.Image too)
  gz_version:=garden      the simulator is Garden (default: the GZ_VERSION variable)
  override_frame_id:=FRAME      set header.frame_id of every bridged message
  override_timestamps_with_wall_time:=true   set header.stamp to the wall time

Example:
  image_bridge /camera /depth:=depth/image --ros-args -p qos:=sensor_data -p camera_info:=true
"""


@dataclass(frozen=True)
class ImageTopic:
    """One topic argument: where the images come from in Gazebo and go to in ROS."""

    gz_topic: str
    ros_topic: str
    #: e.g. ``"argument 2 '/a:=b'"``.
    source: str = ""


def split_ros_args(args: Sequence[str]) -> tuple[list[str], list[str]]:
    """``args`` (without the program name) split into (ROS arguments, the others).

    ROS arguments are the ``--ros-args ... [--]`` sections, markers included, as rcl reads
    them. rclpy gets only those: rcl would read a ``GZ:=ROS`` topic argument outside them as a
    deprecated ROS 1 style remap rule.
    """
    ros: list[str] = []
    other: list[str] = []
    in_ros = False
    for arg in args:
        if arg == ROS_ARGS_START:
            in_ros = True
        (ros if in_ros else other).append(arg)
        if in_ros and arg == ROS_ARGS_END:
            in_ros = False
    return ros, other


def wants_help(args: Sequence[str]) -> bool:
    """Whether the (non-ROS) arguments ask for the usage text."""
    return any(arg in ("-h", "--help") for arg in args)


def parse_topic_args(args: Sequence[str]) -> tuple[ImageTopic, ...]:
    """The topic arguments (ROS arguments already removed), in order, without repeats.

    Raises:
        UsageError: an option we do not know, a rename with an empty side, or a topic with
            types (parameter_bridge's syntax).
    """
    topics: list[ImageTopic] = []
    for index, arg in enumerate(args, start=1):
        source = f"argument {index} '{arg}'"
        if arg.startswith("-"):
            msg = "unknown option; topics cannot start with '-' (image_bridge -h shows usage)"
            raise UsageError(msg, source)
        typed = min((arg.find(c) for c in "@[]" if c in arg), default=-1)
        if typed >= 0:
            msg = (
                "image_bridge takes topic names only, each an image topic: write "
                f"'{arg[:typed] or 'TOPIC'}' (TOPIC@ROS_TYPE@GZ_TYPE is parameter_bridge's syntax)"
            )
            raise UsageError(msg, source)
        gz_topic, rename, ros_topic = arg.partition(RENAME)
        if not rename:
            ros_topic = gz_topic
        if not gz_topic or not ros_topic:
            msg = f"write GZ_TOPIC{RENAME}ROS_TOPIC with both names, or one TOPIC for both"
            raise UsageError(msg, source)
        topic = ImageTopic(gz_topic, ros_topic, source)
        if all((t.gz_topic, t.ros_topic) != (gz_topic, ros_topic) for t in topics):
            topics.append(topic)
    return tuple(topics)


def qos_profile_name(value: str) -> str | None:
    """The ``qos_profile`` for a ``qos`` parameter value (None: the default profile).

    Raises:
        ConfigError: an unknown value; the message is ros_gz_image's log line.
    """
    try:
        return QOS_CHOICES[value]
    except KeyError:
        choices = ", ".join(QOS_CHOICES)
        msg = (
            f"Invalid QoS profile {value} specified. Using default profile. "
            f"(qos is one of {choices})"
        )
        raise ConfigError(msg) from None


def check_gz_type(value: str) -> str:
    """``value`` if it names the Gazebo Image type in one of its two spellings.

    Raises:
        ConfigError: any other value.
    """
    if value in GZ_IMAGE_TYPES:
        return value
    msg = f"gz_type must be one of {', '.join(GZ_IMAGE_TYPES)}, got {value!r}"
    raise ConfigError(msg)


def camera_info_topic(image_topic: str) -> str:
    """The camera_info topic beside ``image_topic`` (its last name token replaced).

    Absolute names stay absolute and relative names relative, so the ROS side resolves in the
    node namespace like the image topic.
    """
    head, slash, _last = image_topic.rstrip("/").rpartition("/")
    return f"{head}{slash}{CAMERA_INFO_NAME}"


def camera_info_type(gz_image_type: str) -> str:
    """``gz.msgs.CameraInfo`` or ``ignition.msgs.CameraInfo``, spelled like the image type."""
    return gz_image_type.rpartition(".")[0] + ".CameraInfo"


def topic_specs(topics: Iterable[ImageTopic], gz_type: str) -> tuple[TopicBridgeSpec, ...]:
    """One Gazebo->ROS Image bridge per topic argument."""
    return tuple(
        TopicBridgeSpec(
            ros_topic=topic.ros_topic,
            gz_topic=topic.gz_topic,
            ros_type=IMAGE_ROS_TYPE,
            gz_type=gz_type,
            direction=Direction.GZ_TO_ROS,
            source=topic.source,
        )
        for topic in topics
    )


def select_config_entries(result: ParseResult) -> ParseResult:
    """Keep the Image and CameraInfo topic entries of a parameter_bridge config, Gazebo->ROS.

    A BIDIRECTIONAL entry (the YAML default) is bridged Gazebo->ROS. ROS->Gazebo entries,
    other types and services are skipped with a warning each: that file's other entries are
    parameter_bridge's job.
    """
    kept: list[BridgeSpec] = []
    warnings = list(result.warnings)
    wanted = (IMAGE_ROS_TYPE, CAMERA_INFO_ROS_TYPE)
    for spec in result.specs:
        if not isinstance(spec, TopicBridgeSpec) or spec.ros_type not in wanted:
            kind = "service" if not isinstance(spec, TopicBridgeSpec) else spec.ros_type
            warnings.append(
                f"{spec.source}: skipped ({kind}): image_bridge bridges only "
                f"{IMAGE_ROS_TYPE} and {CAMERA_INFO_ROS_TYPE} entries; use parameter_bridge "
                "for the others"
            )
        elif spec.direction is Direction.ROS_TO_GZ:
            warnings.append(
                f"{spec.source}: skipped: image_bridge bridges Gazebo->ROS only, "
                "this entry is ROS_TO_GZ"
            )
        else:
            kept.append(dataclasses.replace(spec, direction=Direction.GZ_TO_ROS))
    return ParseResult(tuple(kept), result.errors, tuple(warnings))


def with_camera_info(specs: Iterable[TopicBridgeSpec]) -> tuple[TopicBridgeSpec, ...]:
    """``specs`` plus a CameraInfo bridge beside each Image bridge that has none yet."""
    result = list(specs)
    for spec in list(result):
        if spec.ros_type != IMAGE_ROS_TYPE:
            continue
        info = dataclasses.replace(
            spec,
            ros_topic=camera_info_topic(spec.ros_topic),
            gz_topic=camera_info_topic(spec.gz_topic),
            ros_type=CAMERA_INFO_ROS_TYPE,
            gz_type=camera_info_type(spec.gz_type),
            source=f"{spec.source} (camera_info)",
        )
        if all((s.ros_topic, s.ros_type) != (info.ros_topic, info.ros_type) for s in result):
            result.append(info)
    return tuple(result)


def with_qos(specs: Iterable[TopicBridgeSpec], profile: str | None) -> tuple[TopicBridgeSpec, ...]:
    """Apply the ``qos`` parameter to the specs that set neither a profile nor a queue."""
    if profile is None:
        return tuple(specs)
    return tuple(
        dataclasses.replace(spec, qos_profile=profile)
        if spec.qos_profile is None and spec.publisher_queue is None
        else spec
        for spec in specs
    )
