"""parameter_bridge argument parsing: docs/behaviour.md §2.1-§2.4 and the README inline forms."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import (
    USAGE,
    Direction,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    UsageError,
    parse_cli_args,
)
from ros_gz_bridge_py.errors import ConfigError


def _one(arg: str) -> TopicBridgeSpec | ServiceBridgeSpec:
    result = parse_cli_args([arg])
    assert result.errors == ()
    (spec,) = result.specs
    return spec


@pytest.mark.parametrize(
    ("arg", "ros_type", "gz_type", "direction"),
    [
        (
            "/chatter@std_msgs/msg/String@gz.msgs.StringMsg",
            "std_msgs/msg/String",
            "gz.msgs.StringMsg",
            Direction.BIDIRECTIONAL,
        ),
        (
            "/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
            "rosgraph_msgs/msg/Clock",
            "gz.msgs.Clock",
            Direction.GZ_TO_ROS,
        ),
        (
            "/cmd_vel@geometry_msgs/msg/Twist]ignition.msgs.Twist",
            "geometry_msgs/msg/Twist",
            "ignition.msgs.Twist",
            Direction.ROS_TO_GZ,
        ),
    ],
)
def test_topic_directions(arg: str, ros_type: str, gz_type: str, direction: Direction) -> None:
    name = arg.split("@", 1)[0]
    assert _one(arg) == TopicBridgeSpec(
        ros_topic=name,
        gz_topic=name,
        ros_type=ros_type,
        gz_type=gz_type,
        direction=direction,
        source="argument 1",
    )


def test_service_with_default_gz_types() -> None:
    assert _one("/w/control@ros_gz_interfaces/srv/ControlWorld") == ServiceBridgeSpec(
        "/w/control", "ros_gz_interfaces/srv/ControlWorld", None, None, "argument 1"
    )


def test_service_with_explicit_gz_types() -> None:
    spec = _one(
        "/w/control@ros_gz_interfaces/srv/ControlWorld@gz.msgs.WorldControl@gz.msgs.Boolean"
    )
    assert spec == ServiceBridgeSpec(
        "/w/control",
        "ros_gz_interfaces/srv/ControlWorld",
        "gz.msgs.WorldControl",
        "gz.msgs.Boolean",
        "argument 1",
    )


def test_unknown_service_type_is_left_to_the_registry() -> None:
    assert _one("/x@foo/srv/Bar") == ServiceBridgeSpec("/x", "foo/srv/Bar", source="argument 1")


@pytest.mark.parametrize(
    ("arg", "problem"),
    [
        (
            "/w/control@ros_gz_interfaces/srv/ControlWorld@gz.msgs.WorldControl",
            "both Gazebo types or neither",
        ),
        (
            "/w/control@ros_gz_interfaces/srv/ControlWorld[gz.msgs.WorldControl",
            "a service bridge has no direction symbol",
        ),
        ("/w/control@ros_gz_interfaces/srv/ControlWorld]gz.msgs.X", "no direction symbol"),
        ("chatter", "no '@' after the topic or service name"),
        ("@a@b", "no topic or service name before the first '@'"),
        ("t@A@B@C", "more than one '@' after the ROS type"),
        ("t@A@", "no Gazebo type after the direction symbol"),
        ("t@A[", "no Gazebo type after the direction symbol"),
        ("t@]x", "no ROS type before ']'"),
        ("t@", "no ROS type after the first '@'"),
        ("t@@x", "no ROS type after the first '@'"),
        ("t@[x", "no ROS type after the first '@'"),
        ("-h", "no '@'"),
    ],
)
def test_usage_errors_name_the_argument(arg: str, problem: str) -> None:
    with pytest.raises(UsageError, match=problem) as caught:
        parse_cli_args(["/ok@std_msgs/msg/String@gz.msgs.StringMsg", arg])
    assert caught.value.source == f"argument 2 '{arg}'"
    assert isinstance(caught.value, ConfigError)


def test_missing_gz_type_is_an_error_with_the_fix() -> None:
    with pytest.raises(UsageError) as caught:
        parse_cli_args(["/a@std_msgs/msg/Bool[gz.msgs.Boolean", "/t@std_msgs/msg/String"])
    assert str(caught.value) == (
        "argument 2 '/t@std_msgs/msg/String': no Gazebo type; write "
        "/t@std_msgs/msg/String@gz.msgs.X ([ for Gazebo->ROS, ] for ROS->Gazebo)"
    )


@pytest.mark.parametrize("symbol", ["<", ">", "|", "-"])
def test_a_symbol_that_is_no_direction_is_named(symbol: str) -> None:
    """The hint was to append '@gz.msgs.X' to the whole argument, the bad symbol kept."""
    arg = f"/clock@rosgraph_msgs/msg/Clock{symbol}gz.msgs.Clock"
    with pytest.raises(UsageError) as caught:
        parse_cli_args([arg])
    assert str(caught.value) == (
        f"argument 1 '{arg}': '{symbol}' is no direction symbol; between the ROS and the "
        "Gazebo type write @ (both ways), [ (Gazebo->ROS) or ] (ROS->Gazebo)"
    )


def test_ros_type_without_msg_is_kept_with_a_hint() -> None:
    result = parse_cli_args(["/t@std_msgs/String@gz.msgs.StringMsg"])
    (spec,) = result.specs
    assert isinstance(spec, TopicBridgeSpec)
    assert spec.ros_type == "std_msgs/String"
    assert result.warnings == (
        "argument 1: ROS type 'std_msgs/String' has no '/msg/' and will not be found; "
        "did you mean std_msgs/msg/String",
    )


def test_at_takes_precedence_over_brackets() -> None:
    result = parse_cli_args(["a@T[x@y"])
    (spec,) = result.specs
    assert isinstance(spec, TopicBridgeSpec)
    assert (spec.ros_type, spec.gz_type, spec.direction) == ("T[x", "y", Direction.BIDIRECTIONAL)
    assert len(result.warnings) == 1
    assert "contains '['" in result.warnings[0]


def test_bracket_wins_over_later_close_bracket() -> None:
    spec = _one("t@A]B[C")
    assert isinstance(spec, TopicBridgeSpec)
    assert (spec.ros_type, spec.gz_type, spec.direction) == ("A]B", "C", Direction.GZ_TO_ROS)


def test_no_arguments_is_an_empty_result() -> None:
    result = parse_cli_args([])
    assert (result.specs, result.errors, result.warnings) == ((), (), ())


def test_readme_inline_forms() -> None:
    args = [
        "/cmd_vel@geometry_msgs/msg/Twist[ignition.msgs.Twist",
        "/joint_states@sensor_msgs/msg/JointState[ignition.msgs.Model",
        "/imu@sensor_msgs/msg/Imu[ignition.msgs.IMU",
        "/cmd_vel@geometry_msgs/msg/Twist@gz.msgs.Twist",
        "/scan@sensor_msgs/msg/LaserScan@gz.msgs.LaserScan",
        "/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
    ]
    result = parse_cli_args(args)
    assert result.warnings == ()
    summary = [
        (s.ros_topic, s.ros_type, s.gz_type, s.direction, s.source)
        for s in result.specs
        if isinstance(s, TopicBridgeSpec)
    ]
    assert summary == [
        (
            "/cmd_vel",
            "geometry_msgs/msg/Twist",
            "ignition.msgs.Twist",
            Direction.GZ_TO_ROS,
            "argument 1",
        ),
        (
            "/joint_states",
            "sensor_msgs/msg/JointState",
            "ignition.msgs.Model",
            Direction.GZ_TO_ROS,
            "argument 2",
        ),
        ("/imu", "sensor_msgs/msg/Imu", "ignition.msgs.IMU", Direction.GZ_TO_ROS, "argument 3"),
        (
            "/cmd_vel",
            "geometry_msgs/msg/Twist",
            "gz.msgs.Twist",
            Direction.BIDIRECTIONAL,
            "argument 4",
        ),
        (
            "/scan",
            "sensor_msgs/msg/LaserScan",
            "gz.msgs.LaserScan",
            Direction.BIDIRECTIONAL,
            "argument 5",
        ),
        ("/clock", "rosgraph_msgs/msg/Clock", "gz.msgs.Clock", Direction.GZ_TO_ROS, "argument 6"),
    ]


def test_usage_text_covers_every_form() -> None:
    for example in (
        "/chatter@std_msgs/msg/String@gz.msgs.StringMsg",
        "/chatter@std_msgs/msg/String[gz.msgs.StringMsg",
        "/chatter@std_msgs/msg/String]gz.msgs.StringMsg",
        "/world/default/control@ros_gz_interfaces/srv/ControlWorld\n",
        "ControlWorld@gz.msgs.WorldControl@gz.msgs.Boolean",
    ):
        assert example in USAGE
    # Every example in the usage text parses.
    examples = [line.split()[1] for line in USAGE.splitlines() if "parameter_bridge /" in line]
    assert len(parse_cli_args(examples).specs) == 5
