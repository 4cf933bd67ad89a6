"""Bridge YAML files: the C++ config tests (docs/behaviour.md §4.4) and located errors; the real
files of ``config/`` are read in test_yaml_file_real_configs.py."""

from __future__ import annotations

from pathlib import Path

import pytest

from ros_gz_bridge_py.config import (
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    parse_yaml,
    read_yaml_file,
)

FIXTURES = Path(__file__).parent / "fixtures"


_TYPES = "  ros_type_name: std_msgs/msg/String\n  gz_type_name: gz.msgs.StringMsg\n"


def _topics(result: ParseResult) -> list[TopicBridgeSpec]:
    topics = [spec for spec in result.specs if isinstance(spec, TopicBridgeSpec)]
    assert len(topics) == len(result.specs)
    return topics


def _only_error(result: ParseResult) -> str:
    assert result.specs == ()
    (error,) = result.errors
    return error.message


def test_minimum() -> None:
    result = read_yaml_file(FIXTURES / "minimum.yaml")
    assert (result.errors, result.warnings) == ((), ())
    names = [(s.ros_topic, s.gz_topic) for s in _topics(result)]
    assert names == [
        ("chatter", "chatter"),
        ("chatter_ros", "chatter_ros"),
        ("chatter_gz", "chatter_gz"),
        ("chatter_both_ros", "chatter_both_gz"),
    ]
    for spec in _topics(result):
        assert (spec.ros_type, spec.gz_type) == ("std_msgs/msg/String", "ignition.msgs.StringMsg")
        assert spec.direction is Direction.BIDIRECTIONAL
        # Unset: the bridge applies the defaults (queues 10, the node's lazy).
        assert (spec.publisher_queue, spec.subscriber_queue, spec.lazy) == (None, None, None)
        assert (spec.qos_profile, spec.frame_id) == (None, None)


def test_full() -> None:
    path = FIXTURES / "full.yaml"
    first, second = _topics(read_yaml_file(path))
    assert first == TopicBridgeSpec(
        ros_topic="ros_chatter",
        gz_topic="gz_chatter",
        ros_type="std_msgs/msg/String",
        gz_type="ignition.msgs.StringMsg",
        direction=Direction.ROS_TO_GZ,
        lazy=True,
        publisher_queue=6,
        subscriber_queue=5,
        source=f"{path} entry 1 (line 2)",
    )
    assert (second.publisher_queue, second.subscriber_queue, second.lazy) == (20, 10, False)
    assert second.direction is Direction.GZ_TO_ROS
    assert second.source == f"{path} entry 2 (line 11)"


@pytest.mark.parametrize(
    ("yaml_text", "message"),
    [
        (
            "\n- topic_name: foo\n  ros_topic_name: bar",
            "Could not parse entry: topic_name and ros_topic_name are mutually exclusive",
        ),
        (
            "\n- topic_name: foo\n  gz_topic_name: bar",
            "Could not parse entry: topic_name and gz_topic_name are mutually exclusive",
        ),
    ],
    ids=["InvalidSetTwoRos", "InvalidSetTwoGz"],
)
def test_invalid_sets(yaml_text: str, message: str) -> None:
    result = parse_yaml(yaml_text)
    assert _only_error(result) == message
    assert result.errors[0].source == "<string> entry 1 (line 2)"


def test_a_left_out_type_is_completed_by_discovery() -> None:
    """C++'s InvalidSetTypes case ("both ros_type_name and gz_type_name must be set"): ours
    takes the missing type from discovery when the bridge runs (docs/many-topics.md, "Templates
    and wildcards"), so the entry is a pattern, not an error."""
    result = parse_yaml("\n- topic_name: foo\n  ros_type_name: bar")
    assert (result.specs, result.errors) == ((), ())
    (pattern,) = result.patterns
    assert (pattern.gz_topic, pattern.ros_topic, pattern.ros_type, pattern.gz_type) == (
        "foo", "", "bar", ""
    )  # fmt: skip
    assert pattern.direction is None
    assert pattern.source == "<string> entry 1 (line 2)"


_ENTRY = """
  - topic_name: foo
    ros_type_name: std_msgs/msg/String
    gz_type_name: ignition.msgs.StringMsg
"""


@pytest.mark.parametrize(
    ("extra", "direction"),
    [
        ("", Direction.BIDIRECTIONAL),
        ("    direction: BIDIRECTIONAL\n", Direction.BIDIRECTIONAL),
        ("    direction: ROS_TO_GZ\n", Direction.ROS_TO_GZ),
        ("    direction: GZ_TO_ROS\n", Direction.GZ_TO_ROS),
    ],
)
def test_parse_direction(extra: str, direction: Direction) -> None:
    (spec,) = _topics(parse_yaml(_ENTRY + extra))
    assert spec.direction is direction


def test_parse_direction_invalid() -> None:
    result = parse_yaml(_ENTRY + "    direction: foobar\n")
    assert _only_error(result) == "Could not parse entry: invalid direction [foobar]"


def test_file_does_not_exist() -> None:
    result = read_yaml_file("this/should/never/be/a/file.yaml")
    assert _only_error(result) == (
        "Could not parse config: failed to open file [this/should/never/be/a/file.yaml]"
    )


def test_top_level_map() -> None:
    result = read_yaml_file(FIXTURES / "invalid.yaml")
    assert _only_error(result) == "Could not parse config: top level must be a YAML sequence"


def test_empty_file() -> None:
    path = FIXTURES / "empty.yaml"
    assert _only_error(read_yaml_file(path)) == f"Could not parse config: file empty [{path}]"


@pytest.mark.parametrize("text", ["", "# only a comment\n", "   \n", "42", "just text"])
def test_top_level_not_a_sequence(text: str) -> None:
    message = _only_error(parse_yaml(text))
    assert message == "Could not parse config: top level must be a YAML sequence"


def test_empty_list_is_no_bridges_and_no_error() -> None:
    assert parse_yaml("[]") == ParseResult()


def test_invalid_entry_is_skipped_and_the_others_kept() -> None:
    text = """\
- topic_name: a
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
- just a string
- topic_name: b
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  direction: sideways
- topic_name: c
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
"""
    result = parse_yaml(text, "bridge.yaml")
    assert [s.ros_topic for s in _topics(result)] == ["a", "c"]
    assert [(e.source, e.message) for e in result.errors] == [
        ("bridge.yaml entry 2 (line 4)", "Could not parse entry: entry must be a YAML map"),
        ("bridge.yaml entry 3 (line 8)", "Could not parse entry: invalid direction [sideways]"),
    ]
    assert str(result.errors[1]) == (
        "bridge.yaml entry 3 (line 8): Could not parse entry: invalid direction [sideways]"
    )


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("publisher_queue: abc", "publisher_queue must be a non-negative integer, got 'abc'"),
        ("subscriber_queue: -3", "subscriber_queue must be a non-negative integer, got -3"),
        ("subscriber_queue: 2.5", "subscriber_queue must be a non-negative integer, got 2.5"),
        ("publisher_queue: true", "publisher_queue must be a non-negative integer, got True"),
        ("publisher_queue: 16777217", "publisher_queue must be at most 16777216, got 16777217"),
        (
            "subscriber_queue: 99999999999999999999",
            "subscriber_queue must be at most 16777216, got 99999999999999999999",
        ),
        ("lazy: maybe", "lazy must be true or false, got 'maybe'"),
        ("lazy: 1", "lazy must be true or false, got 1"),
        ("ros_topic_name: {a: 1}", "ros_topic_name must be a string, got a map"),
        ("frame_id: [a, b]", "frame_id must be a string, got a list"),
        ("qos_profile: FAST", "invalid qos_profile [FAST]; use one of BEST_AVAILABLE, CLOCK,"),
    ],
)
def test_wrong_value_types_are_located_errors(line: str, message: str) -> None:
    text = f"""\
- gz_topic_name: g
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  {line}
"""
    result = parse_yaml(text, "b.yaml")
    assert _only_error(result).startswith(f"Could not parse entry: {message}")
    assert result.errors[0].source == "b.yaml entry 1 (line 4)"


def test_syntax_error_is_one_located_error() -> None:
    result = parse_yaml("- topic_name: [unclosed\n- other: 1\n", "bad.yaml")
    message = _only_error(result)
    assert message.startswith("Could not parse config: invalid YAML: ")
    assert result.errors[0].source is not None
    assert result.errors[0].source.startswith("bad.yaml (line ")


def test_two_documents_are_a_syntax_error() -> None:
    message = _only_error(parse_yaml("- a: 1\n---\n- b: 2\n"))
    assert message.startswith("Could not parse config: invalid YAML: ")


def test_unsafe_tags_are_refused() -> None:
    text = """\
- topic_name: t
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  lazy: !!python/object/apply:os.system ["true"]
"""
    result = parse_yaml(text)
    assert "could not determine a constructor" in _only_error(result)


def test_optional_keys() -> None:
    text = """\
- ros_topic_name: points
  gz_topic_name: /model/car/points
  ros_type_name: sensor_msgs/msg/PointCloud2
  gz_type_name: gz.msgs.PointCloudPacked
  direction: GZ_TO_ROS
  qos_profile: SENSOR_DATA
  frame_id: lidar_link
  lazy: yes
  publisher_queue: "3"
"""
    (spec,) = _topics(parse_yaml(text))
    assert (spec.ros_topic, spec.gz_topic) == ("points", "/model/car/points")
    assert (spec.qos_profile, spec.frame_id, spec.lazy) == ("SENSOR_DATA", "lidar_link", True)
    assert (spec.publisher_queue, spec.subscriber_queue) == (3, None)


def test_empty_string_counts_as_unset() -> None:
    text = """\
- topic_name: ""
  ros_topic_name: x
  gz_topic_name:
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  frame_id: ""
  qos_profile: ""
"""
    (spec,) = _topics(parse_yaml(text))
    assert (spec.ros_topic, spec.gz_topic, spec.frame_id, spec.qos_profile) == (
        "x",
        "x",
        None,
        None,
    )


def test_scalar_names_keep_their_text() -> None:
    text = "- topic_name: 0123\n" + _TYPES
    (spec,) = _topics(parse_yaml(text))
    assert spec.ros_topic == "0123"


def test_entry_without_any_name_is_an_error() -> None:
    text = "- ros_type_name: std_msgs/msg/String\n  gz_type_name: gz.msgs.StringMsg\n"
    assert _only_error(parse_yaml(text)) == (
        "Could not parse entry: one of topic_name, ros_topic_name or gz_topic_name must be set"
    )


def test_services() -> None:
    text = """\
- service_name: /world/default/control
  ros_type_name: ros_gz_interfaces/srv/ControlWorld
- service_name: /world/default/create
  ros_type_name: ros_gz_interfaces/srv/SpawnEntity
  gz_req_type_name: gz.msgs.EntityFactory
  gz_rep_type_name: gz.msgs.Boolean
  direction: GZ_TO_ROS
"""
    result = parse_yaml(text, "s.yaml")
    assert result.specs == (
        ServiceBridgeSpec(
            "/world/default/control",
            "ros_gz_interfaces/srv/ControlWorld",
            source="s.yaml entry 1 (line 1)",
        ),
        ServiceBridgeSpec(
            "/world/default/create",
            "ros_gz_interfaces/srv/SpawnEntity",
            "gz.msgs.EntityFactory",
            "gz.msgs.Boolean",
            "s.yaml entry 2 (line 3)",
        ),
    )
    assert result.warnings == (
        "s.yaml entry 2 (line 3): direction does not apply to a service bridge; it is ignored",
    )


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (
            "  topic_name: x\n",
            "Could not parse entry: service_name and topic_name are mutually exclusive",
        ),
        (
            "  gz_req_type_name: gz.msgs.Entity\n",
            "Could not parse entry: set both gz_req_type_name and gz_rep_type_name, or neither",
        ),
    ],
)
def test_invalid_services(extra: str, message: str) -> None:
    text = "- service_name: /remove\n  ros_type_name: ros_gz_interfaces/srv/DeleteEntity\n" + extra
    assert _only_error(parse_yaml(text)) == message


@pytest.mark.parametrize("gz_type", ["", "  gz_type_name: gz.msgs.WorldControl\n"])
def test_a_service_type_in_a_topic_entry_is_told_to_use_service_name(gz_type: str) -> None:
    """Without a Gazebo type it was left to discovery as a topic, silently (found by a new
    user); with one, the error spoke of a missing converter."""
    text = "- topic_name: /world/control\n  ros_type_name: ros_gz_interfaces/srv/ControlWorld\n"
    assert _only_error(parse_yaml(text + gz_type)) == (
        "Could not parse entry: ros_gz_interfaces/srv/ControlWorld is a service type; bridge "
        "the service with service_name: /world/control (instead of the topic keys)"
    )


def test_service_needs_a_ros_type() -> None:
    message = _only_error(parse_yaml("- service_name: /remove\n"))
    assert message == "Could not parse entry: ros_type_name must be set for a service"


def test_merge_keys_share_settings() -> None:
    text = """\
- &base
  topic_name: a
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  direction: GZ_TO_ROS
- <<: *base
  topic_name: b
"""
    result = parse_yaml(text)
    first, second = _topics(result)
    assert (second.ros_topic, second.ros_type, second.direction) == (
        "b",
        first.ros_type,
        Direction.GZ_TO_ROS,
    )
    assert result.warnings == ()  # overriding a merged key is no duplicate


def test_merge_from_a_flow_map_overrides_without_warning() -> None:
    text = """\
- &base {ros_topic_name: /a, gz_topic_name: /a, ros_type_name: std_msgs/msg/String,
         gz_type_name: gz.msgs.StringMsg, direction: GZ_TO_ROS}
- &b
  <<: *base
  ros_topic_name: /b
- *b
"""
    result = parse_yaml(text)
    assert [(s.ros_topic, s.gz_topic) for s in _topics(result)] == [
        ("/a", "/a"),
        ("/b", "/a"),
        ("/b", "/a"),  # the alias reads entry 2 as written, not its merged form
    ]
    assert result.warnings == ()


def test_duplicate_key_beside_a_merge_still_warns() -> None:
    text = "- &base {topic_name: a}\n- <<: *base\n  topic_name: b\n  topic_name: c\n" + _TYPES
    result = parse_yaml(text)
    assert [s.ros_topic for s in result.specs if isinstance(s, TopicBridgeSpec)] == ["c"]
    assert result.warnings == (
        "<string> entry 2 (line 2): key 'topic_name' is set twice; the last value is used",
    )


def test_duplicate_key_warns_and_last_wins() -> None:
    text = "- topic_name: a\n  topic_name: b\n" + _TYPES
    result = parse_yaml(text)
    (spec,) = _topics(result)
    assert spec.ros_topic == "b"
    assert result.warnings == (
        "<string> entry 1 (line 1): key 'topic_name' is set twice; the last value is used",
    )


def test_non_utf8_file(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes("- topic_name: caf\xe9\n".encode("latin-1"))
    assert _only_error(read_yaml_file(path)) == (
        f"Could not parse config: file is not UTF-8 text [{path}]"
    )


def test_deepest_queue_is_accepted() -> None:
    result = parse_yaml("- topic_name: a\n  publisher_queue: 16777216\n" + _TYPES)
    (spec,) = _topics(result)
    assert (spec.publisher_queue, result.errors) == (16777216, ())
