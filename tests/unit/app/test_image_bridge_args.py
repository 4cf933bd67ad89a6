"""image_bridge argument and parameter handling (pure functions, no rclpy)."""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest

from ros_gz_bridge_py.app.image_bridge_args import (
    CAMERA_INFO_ROS_TYPE,
    IMAGE_ROS_TYPE,
    ImageTopic,
    camera_info_topic,
    camera_info_type,
    check_gz_type,
    parse_topic_args,
    qos_profile_name,
    select_config_entries,
    split_ros_args,
    topic_specs,
    wants_help,
    with_camera_info,
    with_qos,
)
from ros_gz_bridge_py.config import (
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    UsageError,
    parse_yaml,
)
from ros_gz_bridge_py.errors import ConfigError


def _image(ros: str, gz: str, **changes: Any) -> TopicBridgeSpec:
    spec = TopicBridgeSpec(ros, gz, IMAGE_ROS_TYPE, "gz.msgs.Image", Direction.GZ_TO_ROS)
    return dataclasses.replace(spec, **changes)


def test_each_topic_is_both_names() -> None:
    topics = parse_topic_args(["/camera", "depth/image"])
    assert [(t.gz_topic, t.ros_topic) for t in topics] == [
        ("/camera", "/camera"),
        ("depth/image", "depth/image"),
    ]


def test_rename_form() -> None:
    (topic,) = parse_topic_args(["/world/w/model/m/link/l/sensor/cam/image:=front/image"])
    assert topic.gz_topic == "/world/w/model/m/link/l/sensor/cam/image"
    assert topic.ros_topic == "front/image"
    assert topic.source == "argument 1 '/world/w/model/m/link/l/sensor/cam/image:=front/image'"


def test_repeated_topic_is_bridged_once() -> None:
    assert len(parse_topic_args(["/a", "/a", "/a:=/a", "/a:=/b"])) == 2


@pytest.mark.parametrize("arg", [":=b", "a:=", ":=", "-x", "--qos"])
def test_bad_arguments_name_the_argument(arg: str) -> None:
    with pytest.raises(UsageError, match="argument 2") as raised:
        parse_topic_args(["/ok", arg])
    assert arg in str(raised.value)


@pytest.mark.parametrize(
    ("arg", "topic"),
    [("/camera@sensor_msgs/msg/Image@gz.msgs.Image", "/camera"),
     ("/cam[gz.msgs.Image", "/cam"), ("@sensor_msgs/msg/Image", "TOPIC")],
)  # fmt: skip
def test_parameter_bridge_syntax_is_refused_naming_the_topic_to_write(arg: str, topic: str) -> None:
    """Before, the whole text became the topic: 'failed to resolve name', and the process
    stayed up with nothing bridged."""
    with pytest.raises(UsageError) as raised:
        parse_topic_args([arg])
    assert str(raised.value) == (
        f"argument 1 '{arg}': image_bridge takes topic names only, each an image topic: write "
        f"'{topic}' (TOPIC@ROS_TYPE@GZ_TYPE is parameter_bridge's syntax)"
    )


def test_help_flags() -> None:
    assert wants_help(["/a", "-h"])
    assert wants_help(["--help"])
    assert not wants_help(["/a"])


def test_split_ros_args_keeps_topics_out_of_rcl() -> None:
    args = ["/a:=b", "--ros-args", "-p", "qos:=sensor_data", "--", "/c", "--ros-args", "-r", "x:=y"]
    ros, other = split_ros_args(args)
    assert other == ["/a:=b", "/c"]
    assert ros == ["--ros-args", "-p", "qos:=sensor_data", "--", "--ros-args", "-r", "x:=y"]


def test_split_ros_args_without_ros_args() -> None:
    assert split_ros_args(["/a", "/b"]) == ([], ["/a", "/b"])


@pytest.mark.parametrize(
    ("value", "profile"),
    [("default", None), ("sensor_data", "SENSOR_DATA"), ("system_default", "SYSTEM_DEFAULT")],
)
def test_qos_values(value: str, profile: str | None) -> None:
    assert qos_profile_name(value) == profile


def test_unknown_qos_has_the_ros_gz_image_text() -> None:
    with pytest.raises(ConfigError) as raised:
        qos_profile_name("SENSOR_DATA")
    assert str(raised.value) == (
        "Invalid QoS profile SENSOR_DATA specified. Using default profile. "
        "(qos is one of default, sensor_data, system_default)"
    )


def test_gz_type_accepts_both_spellings() -> None:
    assert check_gz_type("gz.msgs.Image") == "gz.msgs.Image"
    assert check_gz_type("ignition.msgs.Image") == "ignition.msgs.Image"
    with pytest.raises(ConfigError, match="gz_type"):
        check_gz_type("gz.msgs.CameraInfo")


@pytest.mark.parametrize(
    ("image", "info"),
    [
        (
            "/world/w/model/m/link/l/sensor/cam/image",
            "/world/w/model/m/link/l/sensor/cam/camera_info",
        ),
        ("/cam/image_raw", "/cam/camera_info"),
        ("/camera", "/camera_info"),
        ("camera", "camera_info"),
        ("robot1/cam/image/", "robot1/cam/camera_info"),
    ],
)
def test_camera_info_beside_the_image(image: str, info: str) -> None:
    assert camera_info_topic(image) == info


def test_camera_info_type_follows_the_image_spelling() -> None:
    assert camera_info_type("gz.msgs.Image") == "gz.msgs.CameraInfo"
    assert camera_info_type("ignition.msgs.Image") == "ignition.msgs.CameraInfo"


def test_topic_specs_are_gz_to_ros_images() -> None:
    (spec,) = topic_specs([ImageTopic("/g", "r", "argument 1 '/g:=r'")], "ignition.msgs.Image")
    assert spec == TopicBridgeSpec(
        "r",
        "/g",
        IMAGE_ROS_TYPE,
        "ignition.msgs.Image",
        Direction.GZ_TO_ROS,
        source="argument 1 '/g:=r'",
    )


def test_with_camera_info_adds_one_per_camera() -> None:
    specs = with_camera_info(
        [_image("front/image", "/s/cam/image"), _image("front/depth", "/s/cam/depth")]
    )
    infos = [s for s in specs if s.ros_type == CAMERA_INFO_ROS_TYPE]
    assert len(specs) == 3
    (info,) = infos
    assert (info.ros_topic, info.gz_topic, info.gz_type) == (
        "front/camera_info",
        "/s/cam/camera_info",
        "gz.msgs.CameraInfo",
    )
    assert info.direction is Direction.GZ_TO_ROS


def test_with_camera_info_keeps_an_explicit_entry() -> None:
    explicit = TopicBridgeSpec(
        "/c/camera_info", "/other", CAMERA_INFO_ROS_TYPE, "gz.msgs.CameraInfo", Direction.GZ_TO_ROS
    )
    specs = with_camera_info([_image("/c/image", "/c/image"), explicit])
    assert [s for s in specs if s.ros_type == CAMERA_INFO_ROS_TYPE] == [explicit]


def test_with_qos_leaves_entries_that_chose_their_own() -> None:
    own_profile = _image("/a", "/a", qos_profile="SYSTEM_DEFAULT")
    own_queue = _image("/b", "/b", publisher_queue=3)
    plain = _image("/c", "/c")
    result = with_qos([own_profile, own_queue, plain], "SENSOR_DATA")
    assert result == (own_profile, own_queue, _image("/c", "/c", qos_profile="SENSOR_DATA"))
    assert with_qos([plain], None) == (plain,)


CONFIG = """
- ros_topic_name: front/image
  gz_topic_name: /cam/image
  ros_type_name: sensor_msgs/msg/Image
  gz_type_name: gz.msgs.Image
- topic_name: /cam/camera_info
  ros_type_name: sensor_msgs/msg/CameraInfo
  gz_type_name: gz.msgs.CameraInfo
  direction: GZ_TO_ROS
- topic_name: /chatter
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
- topic_name: /to_gz
  ros_type_name: sensor_msgs/msg/Image
  gz_type_name: gz.msgs.Image
  direction: ROS_TO_GZ
- service_name: /world/w/control
  ros_type_name: ros_gz_interfaces/srv/ControlWorld
"""


def test_config_entries_images_only_gz_to_ros() -> None:
    result = select_config_entries(parse_yaml(CONFIG, "cams.yaml"))
    assert [(s.ros_topic, s.ros_type) for s in result.specs if isinstance(s, TopicBridgeSpec)] == [
        ("front/image", IMAGE_ROS_TYPE),
        ("/cam/camera_info", CAMERA_INFO_ROS_TYPE),
    ]
    assert all(
        isinstance(s, TopicBridgeSpec) and s.direction is Direction.GZ_TO_ROS for s in result.specs
    )
    skipped = result.warnings
    assert len(skipped) == 3
    assert "entry 3" in skipped[0]
    assert "std_msgs/msg/String" in skipped[0]
    assert "entry 4" in skipped[1]
    assert "ROS_TO_GZ" in skipped[1]
    assert "entry 5" in skipped[2]
    assert "service" in skipped[2]


def test_config_errors_and_warnings_pass_through() -> None:
    error = ConfigError("Could not parse entry: x", "f.yaml entry 1")
    service = ServiceBridgeSpec("/s", "ros_gz_interfaces/srv/ControlWorld", source="f.yaml entry 2")
    result = select_config_entries(ParseResult((service,), (error,), ("f.yaml: a warning",)))
    assert result.specs == ()
    assert result.errors == (error,)
    assert result.warnings[0] == "f.yaml: a warning"
