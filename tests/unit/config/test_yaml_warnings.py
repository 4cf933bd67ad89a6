"""Warnings of bridge YAML files: what an entry says that the bridge takes otherwise than
written, or not at all (a misspelt or deprecated key, a queue the direction does not read)."""

from __future__ import annotations

from ros_gz_bridge_py.config import Direction, ParseResult, TopicBridgeSpec, parse_yaml

_TYPES = "  ros_type_name: std_msgs/msg/String\n  gz_type_name: gz.msgs.StringMsg\n"


def _topics(result: ParseResult) -> list[TopicBridgeSpec]:
    return [spec for spec in result.specs if isinstance(spec, TopicBridgeSpec)]


def test_unknown_keys_warn_with_a_hint() -> None:
    text = """\
- topic_name: t
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  directon: GZ_TO_ROS
  colour: red
"""
    result = parse_yaml(text, "b.yaml")
    (spec,) = _topics(result)
    assert spec.direction is Direction.BIDIRECTIONAL
    assert result.warnings == (
        "b.yaml entry 1 (line 1): unknown key 'directon' (did you mean 'direction'?) is ignored",
        "b.yaml entry 1 (line 1): unknown key 'colour' is ignored",
    )


def test_a_misspelt_type_key_says_the_entry_waits_for_discovery() -> None:
    """The entry became one that discovery completes, and the warning said only 'ignored'."""
    text = """\
- topic_name: t
  ros_type_name: std_msgs/msg/String
  gz_typename: gz.msgs.StringMsg
- topic_name: u
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  gz_typename: gz.msgs.StringMsg
"""
    result = parse_yaml(text, "b.yaml")
    assert [type(item).__name__ for item in result.specs + result.patterns] == [
        "TopicBridgeSpec",
        "TopicPattern",
    ]
    assert result.warnings == (
        "b.yaml entry 1 (line 1): unknown key 'gz_typename' (did you mean 'gz_type_name'?) is "
        "ignored; without gz_type_name the entry waits for Gazebo discovery to give its types",
        "b.yaml entry 2 (line 4): unknown key 'gz_typename' (did you mean 'gz_type_name'?) is "
        "ignored",
    )


def test_humble_keys_and_directions_are_deprecated_but_accepted() -> None:
    text = """\
- ros_topic_name: chatter
  ign_topic_name: ign_chatter
  ros_type_name: std_msgs/msg/String
  ign_type_name: ignition.msgs.StringMsg
  direction: IGN_TO_ROS
- topic_name: cmd
  ros_type_name: std_msgs/msg/String
  gz_type_name: gz.msgs.StringMsg
  direction: ROS_TO_IGN
"""
    result = parse_yaml(text, "old.yaml")
    first, second = _topics(result)
    assert (first.gz_topic, first.gz_type) == ("ign_chatter", "ignition.msgs.StringMsg")
    assert (first.direction, second.direction) == (Direction.GZ_TO_ROS, Direction.ROS_TO_GZ)
    assert result.warnings == (
        "old.yaml entry 1 (line 1): ign_topic_name is deprecated, migrate to gz_topic_name",
        "old.yaml entry 1 (line 1): ign_type_name is deprecated, migrate to gz_type_name",
        "old.yaml entry 1 (line 1): IGN_TO_ROS constant is deprecated, migrate to GZ_TO_ROS",
        "old.yaml entry 2 (line 6): ROS_TO_IGN constant is deprecated, migrate to ROS_TO_GZ",
    )


def test_ros_type_without_msg_warns() -> None:
    text = "- topic_name: a\n  ros_type_name: std_msgs/String\n  gz_type_name: gz.msgs.StringMsg\n"
    result = parse_yaml(text)
    assert len(result.specs) == 1
    assert result.warnings[0].endswith("did you mean std_msgs/msg/String")


def test_zero_queue_is_kept_with_a_located_warning() -> None:
    text = "- topic_name: a\n" + _TYPES + "  subscriber_queue: 0\n"
    result = parse_yaml(text, "b.yaml")
    (spec,) = _topics(result)
    assert spec.subscriber_queue == 0
    (warning,) = result.warnings
    assert warning.startswith(
        "b.yaml entry 1 (line 1): subscriber_queue 0 means the middleware's default history depth"
    )
    assert "set subscriber_queue to the depth you want" in warning


def test_the_queue_a_one_way_bridge_does_not_read_is_said_to_be_ignored() -> None:
    """publisher_queue on a ROS_TO_GZ entry was ignored without a word (as the C++ bridge)."""
    text = (
        "- topic_name: a\n" + _TYPES + "  direction: ROS_TO_GZ\n  publisher_queue: 5\n"
        "  subscriber_queue: 7\n"
        "- topic_name: b\n" + _TYPES + "  direction: GZ_TO_ROS\n  subscriber_queue: 5\n"
        "- topic_name: c\n" + _TYPES + "  publisher_queue: 5\n  subscriber_queue: 5\n"
    )
    result = parse_yaml(text, "q.yaml")
    assert [spec.subscriber_queue for spec in _topics(result)] == [7, 5, 5]
    assert result.warnings == (
        "q.yaml entry 1 (line 1): publisher_queue does not apply to a ROS_TO_GZ bridge (its "
        "ROS side takes subscriber_queue); it is ignored",
        "q.yaml entry 2 (line 7): subscriber_queue does not apply to a GZ_TO_ROS bridge (its "
        "ROS side takes publisher_queue); it is ignored",
    )
