"""Issue 16 in configuration: the name rule, placeholders, wildcard and typeless entries,
``max_rate``, the auto_bridge patterns; every error names its entry (and line) and the fix."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import (
    Direction,
    TopicBridgeSpec,
    UsageError,
    parse_cli_args,
    parse_parameter_bridges,
    parse_yaml,
)
from ros_gz_bridge_py.config.cli import cli_placeholders
from ros_gz_bridge_py.config.discovered import auto_bridge_rules
from ros_gz_bridge_py.config.names import ros_name_for_gz
from ros_gz_bridge_py.config.templates import parse_assignments
from ros_gz_bridge_py.errors import ConfigError

TYPES = "  ros_type_name: nav_msgs/msg/Odometry\n  gz_type_name: gz.msgs.Odometry\n"


@pytest.mark.parametrize(
    ("gz", "ros"),
    [
        ("/model/box::link/pose", "/model/box/link/pose"),
        ("/world/default/model/my-robot/odometry", "/world/default/model/my_robot/odometry"),
        ("/model/2wd/lidar.points", "/model/_2wd/lidar_points"),
        ("/a//b/", "/a/b"),
        ("/x:y", "/x_y"),
        ("relative/name", "relative/name"),
        ("/::", ""),
        ("/already_valid/name_1", "/already_valid/name_1"),
    ],
)
def test_the_name_rule_makes_valid_ros_names(gz: str, ros: str) -> None:
    assert ros_name_for_gz(gz) == ros


def test_placeholders_make_one_entry_per_value_with_located_sources() -> None:
    text = "- gz_topic_name: /model/${robot}/odometry\n  ros_topic_name: /${robot}/odom\n" + TYPES
    result = parse_yaml(text, "robots.yaml", {"robot": ("r1", "r2")})
    assert result.errors == ()
    assert [(s.gz_topic, s.ros_topic) for s in result.specs if isinstance(s, TopicBridgeSpec)] == [
        ("/model/r1/odometry", "/r1/odom"),
        ("/model/r2/odometry", "/r2/odom"),
    ]
    assert [s.source for s in result.specs] == [
        "robots.yaml entry 1 (line 1) [robot=r1]",
        "robots.yaml entry 1 (line 1) [robot=r2]",
    ]


def test_two_placeholders_make_every_combination() -> None:
    text = "- topic_name: /${world}/${robot}/odom\n" + TYPES
    values = {"robot": ("a", "b"), "world": ("w",)}
    specs = parse_yaml(text, "f.yaml", values).specs
    assert [s.gz_topic for s in specs if isinstance(s, TopicBridgeSpec)] == [
        "/w/a/odom",
        "/w/b/odom",
    ]


def test_a_placeholder_without_a_value_names_the_entry_line_and_the_fix() -> None:
    text = "- topic_name: /ok\n" + TYPES + "- topic_name: /model/${robot}/odom\n" + TYPES
    result = parse_yaml(text, "robots.yaml")
    assert len(result.specs) == 1
    (error,) = result.errors
    assert error.source == "robots.yaml entry 2 (line 4)"
    assert "placeholder ${robot} has no value" in error.message
    assert 'placeholders:="[robot=VALUE]"' in error.message
    assert "robot=VALUE" in error.message


def test_placeholder_values_from_arguments_and_the_parameter() -> None:
    assert cli_placeholders(["robot=r1,r2", "/a@std_msgs/msg/String@gz.msgs.StringMsg"]) == {
        "robot": ("r1", "r2")
    }
    assert parse_assignments(["robot=r1", "robot=r2", "world = w "], "p") == {
        "robot": ("r1", "r2"),
        "world": ("w",),
    }
    with pytest.raises(ConfigError, match="'robot' is not a placeholder value; write NAME=VALUE"):
        parse_assignments(["robot"], "parameter placeholders")


def test_command_line_bridges_take_placeholders() -> None:
    args = ["/model/${robot}/cmd_vel@geometry_msgs/msg/Twist]gz.msgs.Twist", "robot=r1,r2"]
    result = parse_cli_args(args, cli_placeholders(args))
    topics = [spec for spec in result.specs if isinstance(spec, TopicBridgeSpec)]
    assert [(s.source, s.gz_topic) for s in topics] == [
        ("argument 1 [robot=r1]", "/model/r1/cmd_vel"),
        ("argument 1 [robot=r2]", "/model/r2/cmd_vel"),
    ]
    with pytest.raises(UsageError, match=r"placeholder \$\{robot\} has no value"):
        parse_cli_args(args[:1])


def test_a_wildcard_entry_is_a_pattern_matching_discovered_names() -> None:
    text = (
        "- gz_topic_name: /model/*/odometry\n  ros_topic_name: /*/odom\n"
        "  ros_type_name: nav_msgs/msg/Odometry\n  max_rate: 5\n"
        "- topic_name: /world/**/pose\n  direction: GZ_TO_ROS\n"
    )
    result = parse_yaml(text, "w.yaml")
    assert (result.specs, result.errors) == ((), ())
    odometry, pose = result.patterns
    assert odometry.match("/model/r-1/odometry") == ("r-1",)
    assert odometry.match("/model/a/b/odometry") is None
    assert odometry.ros_name("/model/r-1/odometry", ("r-1",)) == "/r_1/odom"
    assert (odometry.ros_type, odometry.gz_type, odometry.max_rate) == (
        "nav_msgs/msg/Odometry",
        "",
        5.0,
    )
    assert odometry.direction is None
    assert pose.match("/world/w/model/m::l/pose") == ("w/model/m::l",)
    assert pose.ros_name("/world/w/model/m::l/pose", ("w/model/m::l",)) == "/world/w/model/m/l/pose"
    assert pose.direction is Direction.GZ_TO_ROS
    assert pose.source == "w.yaml entry 2 (line 5)"


def test_wildcards_of_the_ros_name_must_follow_the_gazebo_name() -> None:
    text = "- gz_topic_name: /model/*/odometry\n  ros_topic_name: /**/odom\n" + TYPES
    (error,) = parse_yaml(text, "w.yaml").errors
    assert error.source == "w.yaml entry 1 (line 1)"
    assert "repeat the Gazebo name's wildcards in the same order" in error.message


@pytest.mark.parametrize(
    ("value", "expected"), [("10", 10.0), ("2.5", 2.5), ("0", 0.0), ("'20'", 20.0)]
)
def test_max_rate_in_yaml(value: str, expected: float) -> None:
    (spec,) = parse_yaml(f"- topic_name: /x\n{TYPES}  max_rate: {value}\n").specs
    assert isinstance(spec, TopicBridgeSpec)
    assert spec.max_rate == expected


@pytest.mark.parametrize("value", ["-1", "fast", ".inf", "[1]"])
def test_a_bad_max_rate_names_the_entry_line_and_the_rule(value: str) -> None:
    result = parse_yaml(f"- topic_name: /x\n{TYPES}  max_rate: {value}\n", "r.yaml")
    (error,) = result.errors
    assert error.source == "r.yaml entry 1 (line 4)"
    assert "max_rate must be a number of messages per second >= 0 (0: no limit)" in error.message


def test_max_rate_as_a_bridge_parameter() -> None:
    values = {
        "bridges.a.ros_type_name": "std_msgs/msg/String",
        "bridges.a.ros_topic_name": "/a",
        "bridges.a.gz_topic_name": "/a",
        "bridges.a.gz_type_name": "gz.msgs.StringMsg",
        "bridges.a.max_rate": 15,
    }
    (spec,) = parse_parameter_bridges(["a"], values.get).specs
    assert isinstance(spec, TopicBridgeSpec)
    assert spec.max_rate == 15.0
    values["bridges.a.max_rate"] = "never"
    (error,) = parse_parameter_bridges(["a"], values.get).errors
    assert "Bridge a has an invalid value: max_rate must be a number" in error.message


def test_auto_bridge_patterns() -> None:
    rules = auto_bridge_rules(True, ["^/model/"], ["camera", r"\.points$"])
    assert rules.admits("/model/r1/odometry")
    assert not rules.admits("/clock")
    assert not rules.admits("/model/r1/camera/image")
    assert not rules.admits("/model/r1/lidar.points")
    assert rules.why_not("/model/r1/camera") == "auto_bridge_deny pattern 'camera' matches it"
    assert rules.why_not("/clock") == "no auto_bridge_allow pattern matches it"
    assert auto_bridge_rules(True, [], []).admits("/anything")


def test_a_bad_pattern_names_the_parameter_index_and_the_fix() -> None:
    with pytest.raises(ConfigError) as caught:
        auto_bridge_rules(True, [], ["ok", "/model/(unclosed"])
    assert "auto_bridge_deny[1] '/model/(unclosed' is not a regular expression" in str(caught.value)
    assert r"escape special characters with \ " in str(caught.value)
