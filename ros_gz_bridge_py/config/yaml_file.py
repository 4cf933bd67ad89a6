"""Bridge YAML files (the ``config_file`` parameter) parsed into specs with located errors.

Keys, precedence and the error texts are the C++ bridge's (docs/behaviour.md §4.1-§4.3); an invalid
entry is skipped and the others still parse. The file is composed (PyYAML ``SafeLoader``) into
a node tree rather than loaded, so every error and warning can name the entry and its line.

Ours beyond C++: ``${name}`` placeholders in any value (``templates.py``; an entry is read once
per combination of values), ``max_rate``, and entries that discovery completes
(``patterns.py``): a Gazebo name with a wildcard, or a left-out type.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar, cast

import yaml
from yaml.constructor import SafeConstructor

from ros_gz_bridge_py.config import templates
from ros_gz_bridge_py.config.model import (
    DEPRECATED_DIRECTIONS,
    QOS_PROFILE_NAMES,
    BridgeSpec,
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    as_bool,
    as_queue,
    as_rate,
    ros_type_hint,
    zero_queue_hint,
)
from ros_gz_bridge_py.config.patterns import TopicPattern, check_wildcards, has_wildcard
from ros_gz_bridge_py.errors import ConfigError

_NAME_KEYS = ("topic_name", "ros_topic_name", "gz_topic_name")
_TOPIC_ONLY_KEYS = (
    "gz_type_name",
    "direction",
    "publisher_queue",
    "subscriber_queue",
    "lazy",
    "qos_profile",
    "frame_id",
    "max_rate",
)
_SERVICE_KEYS = ("service_name", "gz_req_type_name", "gz_rep_type_name")
#: Humble-era spellings of gz_topic_name and gz_type_name.
_DEPRECATED_KEYS = ("ign_topic_name", "ign_type_name")
_KNOWN_KEYS = frozenset(
    (*_NAME_KEYS, "ros_type_name", *_TOPIC_ONLY_KEYS, *_SERVICE_KEYS, *_DEPRECATED_KEYS)
)
_NULL_TAG = "tag:yaml.org,2002:null"
_MERGE_TAG = "tag:yaml.org,2002:merge"
_T = TypeVar("_T")
#: What one entry (or one combination of its placeholders' values) reads as.
Parsed = BridgeSpec | TopicPattern


def _entry_error(text: str, source: str) -> ConfigError:
    return ConfigError(f"Could not parse entry: {text}", source)


class _Entry:
    """The keys of one YAML map entry, read with C++ semantics and located errors."""

    def __init__(
        self, node: yaml.MappingNode, source_name: str, index: int, warnings: list[str]
    ) -> None:
        self._source_name = source_name
        self._index = index
        #: The placeholder values of the combination being read (``templates.py``).
        self.chosen: dict[str, str] = {}
        self.location = self.at(node)
        self._warnings = warnings
        self._constructor = SafeConstructor()
        for key in _keys_set_twice(node):
            self.warn(f"key '{key}' is set twice; the last value is used")
        self._values = self._merged_values(node)

    def _merged_values(self, node: yaml.MappingNode) -> dict[str, yaml.Node]:
        """Key -> value node, with ``<<: *anchor`` merges resolved (the entry's own keys win).

        Resolved in a copy, so the node still reads as written if an alias brings it back as
        another entry.
        """
        flat = yaml.MappingNode(node.tag, list(node.value), node.start_mark, node.end_mark)
        try:
            self._constructor.flatten_mapping(flat)
        except yaml.YAMLError as err:
            msg = f"invalid merge key: {err}"
            raise _entry_error(msg, self.location) from err
        values: dict[str, yaml.Node] = {}
        for key_node, value_node in flat.value:  # merged pairs come first
            if not isinstance(key_node, yaml.ScalarNode):
                msg = "keys must be plain strings"
                raise _entry_error(msg, self.at(key_node))
            values[key_node.value] = value_node
        return values

    def at(self, node: yaml.Node) -> str:
        where = f"{self._source_name} entry {self._index} (line {node.start_mark.line + 1})"
        return where + templates.describe(self.chosen)

    def placeholder_names(self) -> list[str]:
        """The ``${name}`` placeholders of the entry's plain values."""
        return templates.names_in(
            node.value for node in self._values.values() if isinstance(node, yaml.ScalarNode)
        )

    def at_value(self, key: str) -> str:
        """The location of ``key``'s value (the entry's when the key is absent)."""
        node = self._values.get(key)
        return self.at(node) if node is not None else self.location

    def warn(self, text: str) -> None:
        self._warnings.append(f"{self.location}: {text}")

    def has(self, key: str) -> bool:
        node = self._values.get(key)
        return node is not None and node.tag != _NULL_TAG

    def text(self, key: str) -> str:
        """The scalar's text as written (yaml-cpp ``as<std::string>``); "" when unset or null."""
        node = self._values.get(key)
        if node is None or node.tag == _NULL_TAG:
            return ""
        if not isinstance(node, yaml.ScalarNode):
            kind = "map" if isinstance(node, yaml.MappingNode) else "list"
            msg = f"{key} must be a string, got a {kind}"
            raise _entry_error(msg, self.at(node))
        return templates.substitute(cast(str, node.value), self.chosen, self.at(node))

    def value(self, key: str) -> object:
        """The key's value constructed as PyYAML would (int, bool, str, ...); None when unset."""
        node = self._values.get(key)
        if node is None:
            return None
        try:
            value = self._constructor.construct_object(node, deep=True)
        except yaml.YAMLError as err:
            msg = f"{key}: {err}"
            raise _entry_error(msg, self.at(node)) from err
        if isinstance(value, str) and self.chosen:
            return templates.substitute(value, self.chosen, self.at(node))
        return value

    def flag(self, key: str) -> bool | None:
        raw = self.value(key)
        return None if raw is None else self._checked(key, lambda: as_bool(key, raw))

    def queue(self, key: str) -> int | None:
        raw = self.value(key)
        depth = None if raw is None else self._checked(key, lambda: as_queue(key, raw))
        if depth == 0:
            self.warn(zero_queue_hint(key))
        return depth

    def rate(self, key: str) -> float | None:
        raw = self.value(key)
        return None if raw is None else self._checked(key, lambda: as_rate(key, raw))

    def _checked(self, key: str, convert: Callable[[], _T]) -> _T:
        try:
            return convert()
        except ConfigError as err:
            raise _entry_error(err.message, self.at_value(key)) from err

    def unknown_keys(self) -> list[str]:
        return [key for key in self._values if key not in _KNOWN_KEYS]


def _keys_set_twice(node: yaml.MappingNode) -> list[str]:
    """Each repeat of a key among the entry's own keys; a key that a ``<<`` merge also gives
    is no repeat (YAML merge semantics: the entry's own value wins)."""
    seen: set[str] = set()
    repeats: list[str] = []
    for key_node, _ in node.value:
        if not isinstance(key_node, yaml.ScalarNode) or key_node.tag == _MERGE_TAG:
            continue
        if key_node.value in seen:
            repeats.append(key_node.value)
        seen.add(key_node.value)
    return repeats


def _gz_key(entry: _Entry, key: str) -> str:
    """A ``gz_*`` key, or its Humble-era ``ign_*`` spelling (with a warning) if only that is set."""
    old = key.replace("gz_", "ign_", 1)
    value = entry.text(key)
    if entry.has(old):
        entry.warn(f"{old} is deprecated, migrate to {key}")
        value = value or entry.text(old)
    return value


def _direction(entry: _Entry) -> Direction:
    if not entry.has("direction"):
        return Direction.BIDIRECTIONAL
    text = entry.text("direction")
    if text in DEPRECATED_DIRECTIONS:
        replacement = DEPRECATED_DIRECTIONS[text]
        entry.warn(f"{text} constant is deprecated, migrate to {replacement.value}")
        return replacement
    try:
        return Direction(text)
    except ValueError:
        msg = f"invalid direction [{text}]"
        raise _entry_error(msg, entry.at_value("direction")) from None


def _parse_service(entry: _Entry) -> ServiceBridgeSpec:
    for key in _NAME_KEYS:
        if entry.text(key):
            msg = f"service_name and {key} are mutually exclusive"
            raise _entry_error(msg, entry.location)
    ros_type = entry.text("ros_type_name")
    if not ros_type:
        msg = "ros_type_name must be set for a service"
        raise _entry_error(msg, entry.location)
    req_type = entry.text("gz_req_type_name")
    rep_type = entry.text("gz_rep_type_name")
    if bool(req_type) != bool(rep_type):
        msg = "set both gz_req_type_name and gz_rep_type_name, or neither"
        raise _entry_error(msg, entry.location)
    for key in _TOPIC_ONLY_KEYS:
        if entry.has(key):
            entry.warn(f"{key} does not apply to a service bridge; it is ignored")
    return ServiceBridgeSpec(
        entry.text("service_name"), ros_type, req_type or None, rep_type or None, entry.location
    )


#: The queue key a one-way topic bridge does not read, and the one it does: a ROS -> Gazebo
#: bridge's ROS side is a subscription, a Gazebo -> ROS bridge's a publisher.
_ONE_WAY_QUEUES = {
    Direction.ROS_TO_GZ: ("publisher_queue", "subscriber_queue"),
    Direction.GZ_TO_ROS: ("subscriber_queue", "publisher_queue"),
}


def _parse_topic(entry: _Entry) -> TopicBridgeSpec | TopicPattern:
    topic_name = entry.text("topic_name")
    ros_topic = entry.text("ros_topic_name")
    gz_topic = _gz_key(entry, "gz_topic_name")
    ros_type = entry.text("ros_type_name")
    gz_type = _gz_key(entry, "gz_type_name")
    if topic_name and ros_topic:
        msg = "topic_name and ros_topic_name are mutually exclusive"
        raise _entry_error(msg, entry.location)
    if topic_name and gz_topic:
        msg = "topic_name and gz_topic_name are mutually exclusive"
        raise _entry_error(msg, entry.location)
    direction = _direction(entry) if entry.has("direction") else None
    if not (topic_name or ros_topic or gz_topic):
        msg = "one of topic_name, ros_topic_name or gz_topic_name must be set"
        raise _entry_error(msg, entry.location)
    if "/srv/" in ros_type:  # else discovery was asked for a topic of that name, silently
        name = topic_name or ros_topic or gz_topic
        msg = (
            f"{ros_type} is a service type; bridge the service with service_name: {name} "
            "(instead of the topic keys)"
        )
        raise _entry_error(msg, entry.at_value("ros_type_name"))
    completed_by_discovery = not (ros_type and gz_type) or has_wildcard(topic_name or gz_topic)
    if completed_by_discovery:
        gz_topic = topic_name or gz_topic or ros_topic
        ros_topic = ros_topic if ros_topic != gz_topic else ""
        check_wildcards(gz_topic, ros_topic, entry.location)
    else:
        ros_topic = topic_name or ros_topic or gz_topic
        gz_topic = topic_name or gz_topic or ros_topic
    qos_profile = entry.text("qos_profile") or None
    if qos_profile is not None and qos_profile not in QOS_PROFILE_NAMES:
        choices = ", ".join(sorted(QOS_PROFILE_NAMES))
        msg = f"invalid qos_profile [{qos_profile}]; use one of {choices}"
        raise _entry_error(msg, entry.at_value("qos_profile"))
    lazy = entry.flag("lazy")
    publisher_queue = entry.queue("publisher_queue")
    subscriber_queue = entry.queue("subscriber_queue")
    if direction is not None and direction in _ONE_WAY_QUEUES:
        unused, used = _ONE_WAY_QUEUES[direction]
        if entry.has(unused):
            entry.warn(
                f"{unused} does not apply to a {direction.value} bridge (its ROS side takes "
                f"{used}); it is ignored"
            )
    max_rate = entry.rate("max_rate")
    if ros_type and (hint := ros_type_hint(ros_type)):
        entry.warn(hint)
    spec = TopicBridgeSpec(
        ros_topic=ros_topic,
        gz_topic=gz_topic,
        ros_type=ros_type,
        gz_type=gz_type,
        direction=direction or Direction.BIDIRECTIONAL,
        lazy=lazy,
        publisher_queue=publisher_queue,
        subscriber_queue=subscriber_queue,
        qos_profile=qos_profile,
        frame_id=entry.text("frame_id") or None,
        max_rate=max_rate,
        source=entry.location,
    )
    return TopicPattern.from_spec(spec, direction) if completed_by_discovery else spec


def _left_out_type(entry: _Entry, close: list[str]) -> str:
    """What ignoring a misspelt type key does to a topic entry: without that type, the entry
    is one that Gazebo discovery completes (no error, as the C++ bridge gave)."""
    meant = close[0] if close else ""
    if meant not in ("ros_type_name", "gz_type_name") or entry.has(meant):
        return ""
    if entry.text("service_name"):
        return ""
    return f"; without {meant} the entry waits for Gazebo discovery to give its types"


def _parse_entry(
    node: yaml.Node,
    source_name: str,
    index: int,
    warnings: list[str],
    placeholders: templates.Placeholders,
) -> list[Parsed]:
    """The entry, read once per combination of its placeholders' values."""
    if not isinstance(node, yaml.MappingNode):
        location = f"{source_name} entry {index} (line {node.start_mark.line + 1})"
        msg = "entry must be a YAML map"
        raise _entry_error(msg, location)
    entry = _Entry(node, source_name, index, warnings)
    for key in entry.unknown_keys():
        close = difflib.get_close_matches(key, _KNOWN_KEYS, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        entry.warn(f"unknown key '{key}'{hint} is ignored{_left_out_type(entry, close)}")
    parsed: list[Parsed] = []
    for chosen in templates.combinations(entry.placeholder_names(), placeholders, entry.location):
        entry.chosen = chosen
        entry.location = entry.at(node)
        parsed.append(_parse_service(entry) if entry.text("service_name") else _parse_topic(entry))
    return parsed


def parse_yaml(
    text: str, source_name: str = "<string>", placeholders: templates.Placeholders | None = None
) -> ParseResult:
    """Parse the text of a bridge YAML file: a sequence of topic or service entries;
    ``placeholders`` gives the values of ``${name}`` (``templates.py``)."""
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        where = f"{source_name} (line {mark.line + 1})" if mark else source_name
        problem = err.problem or err.context or "syntax error"
        message = f"Could not parse config: invalid YAML: {problem}"
        return ParseResult(errors=(ConfigError(message, where),))
    except yaml.YAMLError as err:
        message = f"Could not parse config: invalid YAML: {err}"
        return ParseResult(errors=(ConfigError(message, source_name),))
    if not isinstance(root, yaml.SequenceNode):
        message = "Could not parse config: top level must be a YAML sequence"
        return ParseResult(errors=(ConfigError(message, source_name),))
    specs: list[BridgeSpec] = []
    patterns: list[TopicPattern] = []
    errors: list[ConfigError] = []
    warnings: list[str] = []
    for index, node in enumerate(root.value, start=1):
        try:
            parsed = _parse_entry(node, source_name, index, warnings, placeholders or {})
        except ConfigError as err:
            errors.append(err)
            continue
        patterns += [item for item in parsed if isinstance(item, TopicPattern)]
        specs += [item for item in parsed if not isinstance(item, TopicPattern)]
    return ParseResult(tuple(specs), tuple(errors), tuple(warnings), tuple(patterns))


def read_yaml_file(
    path: str | os.PathLike[str], placeholders: templates.Placeholders | None = None
) -> ParseResult:
    """Read and parse a bridge YAML file; a missing, empty or non-UTF-8 file is one error."""
    name = os.fspath(path)
    try:
        data = Path(path).read_bytes()
    except OSError:
        message = f"Could not parse config: failed to open file [{name}]"
        return ParseResult(errors=(ConfigError(message, name),))
    if not data:
        message = f"Could not parse config: file empty [{name}]"
        return ParseResult(errors=(ConfigError(message, name),))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        message = f"Could not parse config: file is not UTF-8 text [{name}]"
        return ParseResult(errors=(ConfigError(message, name),))
    return parse_yaml(text, name, placeholders)
