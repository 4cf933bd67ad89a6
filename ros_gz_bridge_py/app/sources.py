"""The sources of ``parameter_bridge``'s configuration, each read into a ``ParseResult``: the
command line, the ``config_file`` YAML and the ``bridges.<name>.*`` parameters, with the
``placeholders`` parameter's values, ``expand_gz_topic_names`` and the ``auto_bridge`` rules;
their problems are logged as they are read.
"""

from __future__ import annotations

import dataclasses
import difflib
from collections.abc import Sequence

from rclpy.node import Node

from ros_gz_bridge_py.app.settings import ParameterBridgeParameters, read_only
from ros_gz_bridge_py.config import (
    BridgeSpec,
    Direction,
    ParseResult,
    TopicBridgeSpec,
    expand_topic_name,
    parse_parameter_bridges,
    read_yaml_file,
    templates,
)
from ros_gz_bridge_py.config.discovered import AutoBridgeRules, auto_bridge_rules
from ros_gz_bridge_py.errors import ConfigError

BRIDGE_PARAMETER_KEYS = (
    "ros_topic_name",
    "gz_topic_name",
    "ros_type_name",
    "gz_type_name",
    "direction",
    "lazy",
    "publisher_queue",
    "subscriber_queue",
    "qos_profile",
    "frame_id",
    "max_rate",
    "service_name",
    "gz_req_type_name",
    "gz_rep_type_name",
)


def bridge_parameter_problem(name: str, bridge_names: Sequence[str]) -> str:
    """What is wrong with the parameter ``name`` given on the command line or in a parameters
    file, if it is a ``bridges.*`` one no bridge takes (rcl keeps it without a word): a bridge
    not in ``bridge_names``, or a key no bridge has. '' for any other name."""
    if not name.startswith("bridges."):
        return ""
    rest = name.removeprefix("bridges.")
    bridge = next((b for b in bridge_names if rest.startswith(f"{b}.")), None)
    if bridge is None:
        listed = ", ".join(bridge_names) or "empty"
        return (
            f"parameter {name} changes nothing: no bridge of bridge_names ({listed}) has it; "
            "add the bridge's name to bridge_names"
        )
    key = rest.removeprefix(f"{bridge}.")
    if key in BRIDGE_PARAMETER_KEYS:
        return ""
    close = difflib.get_close_matches(key, BRIDGE_PARAMETER_KEYS, n=1)
    hint = (
        f"; did you mean bridges.{bridge}.{close[0]}"
        if close
        else f" (a bridge's keys: {', '.join(BRIDGE_PARAMETER_KEYS)})"
    )
    return f"parameter {name} is no key of a bridge, so it changes nothing{hint}"


def parameter_bridge_specs(node: Node, names: Sequence[str]) -> ParseResult:
    """The ``bridges.<name>.*`` bridges (Jazzy 1.0.15+ form)."""
    dynamic = read_only(dynamic_typing=True)
    for name in names:
        for key in BRIDGE_PARAMETER_KEYS:
            node.declare_parameter(f"bridges.{name}.{key}", None, dynamic)

    def get(full_name: str) -> object | None:
        value: object | None = node.get_parameter(full_name).value
        return value

    return parse_parameter_bridges(names, get)


def expand_gz_names(result: ParseResult, node: Node) -> ParseResult:
    """Apply ``expand_gz_topic_names`` to the topic bridges of a config source."""
    specs: list[BridgeSpec] = [
        dataclasses.replace(
            spec,
            gz_topic=expand_topic_name(spec.gz_topic, node.get_namespace(), node.get_name()),
        )
        if isinstance(spec, TopicBridgeSpec)
        else spec
        for spec in result.specs
    ]
    return dataclasses.replace(result, specs=tuple(specs))


def report(node: Node, result: ParseResult) -> None:
    logger = node.get_logger()
    for warning in result.warnings:
        logger.warning(warning)
    for error in result.errors:
        logger.error(str(error))


def collect_sources(
    node: Node, cli: ParseResult, params: ParameterBridgeParameters, values: templates.Placeholders
) -> list[ParseResult]:
    """Every configuration source, its problems reported; ``expand_gz_topic_names`` applied
    to each (the command line's too, unlike C++: ros_gz issue 702)."""
    sources = [expand_if(cli, node, params)]
    if params.shared.config_file:
        yaml_file = read_yaml_file(params.shared.config_file, values)
        sources.append(expand_if(yaml_file, node, params))
    if params.bridge_names:
        sources.append(expand_if(parameter_bridge_specs(node, params.bridge_names), node, params))
    for source in sources:
        report(node, source)
    return sources


def gz_subscriptions(sources: Sequence[ParseResult]) -> int:
    """How many Gazebo topics the entries of ``sources`` subscribe (Gazebo -> ROS, both ways):
    the transport's default receive queue per topic is smaller the more there are."""
    carried = (Direction.GZ_TO_ROS, Direction.BIDIRECTIONAL)
    return sum(
        isinstance(spec, TopicBridgeSpec) and spec.direction in carried
        for source in sources
        for spec in source.specs
    )


def placeholder_values(
    params: ParameterBridgeParameters, cli_values: templates.Placeholders
) -> dict[str, tuple[str, ...]]:
    """The ``placeholders`` parameter's values, then the arguments'.

    Raises:
        ConfigError: an item of the parameter that is not NAME=VALUE.
    """
    from_parameter = templates.parse_assignments(params.placeholders, "parameter placeholders")
    return templates.merge(from_parameter, cli_values)


def discovery_rules(
    node: Node, params: ParameterBridgeParameters, *, enabled: bool
) -> AutoBridgeRules:
    """``auto_bridge`` and its patterns; a bad pattern is logged and auto-bridging stays off."""
    try:
        return auto_bridge_rules(enabled, params.auto_bridge_allow, params.auto_bridge_deny)
    except ConfigError as err:
        node.get_logger().error(f"{err}; auto_bridge is off")
        return AutoBridgeRules()


def expand_if(result: ParseResult, node: Node, params: ParameterBridgeParameters) -> ParseResult:
    """``result`` with ``expand_gz_topic_names`` applied when it is set (patterns too)."""
    if not params.shared.expand_gz_topic_names:
        return result
    expanded = expand_gz_names(result, node)
    patterns = tuple(
        dataclasses.replace(
            pattern,
            gz_topic=expand_topic_name(pattern.gz_topic, node.get_namespace(), node.get_name()),
        )
        for pattern in result.patterns
    )
    return dataclasses.replace(expanded, patterns=patterns)
