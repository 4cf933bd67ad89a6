"""``parameter_bridge``: the node parameters, the configuration sources, and the main loop.

Configuration is parsed completely first (arguments, the ``config_file`` YAML, ``bridge_names``
parameters), then every bridge is created; an entry that fails is reported with its location and
skipped, the others bridge. Unlike the C++ bridge, the YAML file is read once at start (not on
the first heartbeat, and not again on every heartbeat when it fails), and it applies together
with command-line bridges.
"""

from __future__ import annotations

import contextlib
import dataclasses
import sys
from collections.abc import Sequence

import rclpy
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from ros_gz_bridge_py.app.check import DEFAULT_SECONDS as DEFAULT_CHECK_SECONDS
from ros_gz_bridge_py.app.check import Sides, run_check
from ros_gz_bridge_py.app.settings import (
    ParameterBridgeParameters,
    Switches,
    declare_parameter_bridge_parameters,
    read_switches,
)
from ros_gz_bridge_py.config import (
    USAGE,
    BridgeSpec,
    ParseResult,
    TopicBridgeSpec,
    UsageError,
    expand_topic_name,
    parse_cli_args,
    parse_parameter_bridges,
    read_yaml_file,
)
from ros_gz_bridge_py.config.gz_version import check_gz_version
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.core.bridge import Bridge
from ros_gz_bridge_py.core.status import DiagnosticsPublisher, serve, start_diagnostics
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.ros.runtime import apply_speed_settings, make_executor
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import create_gz_node

NODE_NAME = "ros_gz_bridge"
#: ``parameter_bridge --check [SECONDS]``: report on the entries instead of bridging them.
CHECK_OPTION = "--check"
#: Exit status for bad arguments, as the C++ bridge (``return -1``).
USAGE_EXIT = 255
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
    "service_name",
    "gz_req_type_name",
    "gz_rep_type_name",
)


def parameter_bridge_specs(node: Node, names: Sequence[str]) -> ParseResult:
    """The ``bridges.<name>.*`` bridges (Jazzy 1.0.15+ form)."""
    dynamic = ParameterDescriptor(dynamic_typing=True)
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


def main(argv: Sequence[str] | None = None, stop: StopSignal | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = argv[1:]
    positional = remove_ros_args(argv)[1:]
    if any(arg in ("-h", "--help") for arg in positional):
        print(USAGE)
        return 0
    if not args:
        print(USAGE)
        return USAGE_EXIT
    try:
        check_seconds, positional = split_check_option(positional)
        cli = parse_cli_args(positional)
    except UsageError as err:
        print(USAGE)
        print(f"parameter_bridge: {err}", file=sys.stderr)
        return USAGE_EXIT

    if stop is not None and stop.requested:
        return 0
    switches = read_switches()
    apply_speed_settings(fastdds_profile=switches.fastdds_profile)
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    with contextlib.ExitStack() as scope:
        if stop is None:
            stop = scope.enter_context(StopSignal())
        node = Node(NODE_NAME)
        bridge: Bridge | None = None
        diagnostics: DiagnosticsPublisher | None = None
        try:
            params = declare_parameter_bridge_parameters(node)
            if stop.requested:
                return 0
            if check_seconds is not None:
                return check(node, cli, params, switches, check_seconds)
            bridge = build_bridge(node, cli, params, switches)
            diagnostics = start_diagnostics(node, bridge, params.status_period)
            serve(node, bridge, stop, events_executor=switches.events_executor)
        finally:
            if diagnostics is not None:
                diagnostics.close()
            if bridge is not None:
                bridge.close()
            node.destroy_node()
            rclpy.try_shutdown()
    return 0


def split_check_option(args: Sequence[str]) -> tuple[float | None, list[str]]:
    """(``--check`` seconds or None, the other arguments): ``--check [SECONDS]`` anywhere.

    Raises:
        UsageError: the seconds are not a positive number.
    """
    rest = list(args)
    if CHECK_OPTION not in rest:
        return None, rest
    index = rest.index(CHECK_OPTION)
    del rest[index]
    seconds = DEFAULT_CHECK_SECONDS
    if index < len(rest) and not rest[index].startswith("/") and "@" not in rest[index]:
        text = rest.pop(index)
        try:
            seconds = float(text)
        except ValueError:
            seconds = -1.0
        if not seconds > 0:
            msg = f"--check takes a number of seconds > 0 to listen for, not {text!r}"
            raise UsageError(msg, f"argument '{CHECK_OPTION} {text}'")
    return seconds, rest


def collect_sources(
    node: Node, cli: ParseResult, params: ParameterBridgeParameters
) -> list[ParseResult]:
    """Every configuration source, its problems reported."""
    sources = [cli]
    if params.shared.config_file:
        sources.append(expand_if(read_yaml_file(params.shared.config_file), node, params))
    if params.bridge_names:
        sources.append(expand_if(parameter_bridge_specs(node, params.bridge_names), node, params))
    for source in sources:
        report(node, source)
    return sources


def check(
    node: Node,
    cli: ParseResult,
    params: ParameterBridgeParameters,
    switches: Switches,
    seconds: float,
) -> int:
    """``--check``: report on every entry without bridging (:mod:`ros_gz_bridge_py.app.check`)."""
    sources = collect_sources(node, cli, params)
    specs = [spec for source in sources for spec in source.specs]
    errors = sum(len(source.errors) for source in sources)
    if not specs and not errors:
        print("parameter_bridge --check: no entries to check (give topics or config_file)")
        return USAGE_EXIT
    executor = make_executor(events=switches.events_executor)
    executor.add_node(node)
    with create_gz_node(params.shared.gz_node_options()) as gz_node:
        sides = Sides(node, gz_node, default_registry())
        status = run_check(sides, specs, seconds, out=sys.stdout, spin_once=executor.spin_once)
    if errors:
        print(f"{errors} configuration entries could not be read (see the errors above)")
    return 1 if errors else status


def build_bridge(
    node: Node, cli: ParseResult, params: ParameterBridgeParameters, switches: Switches
) -> Bridge:
    """Collect every configuration source, report its problems, and create the bridges."""
    logger = node.get_logger()
    for warning in switches.warnings:
        logger.warning(warning)
    sources = collect_sources(node, cli, params)
    try:
        gz_version = check_gz_version(params.shared.gz_version)
    except ConfigError as err:
        logger.error(str(err))
        gz_version = ""
    bridge = Bridge(
        node,
        options=params.shared.bridge_options(
            switches, gz_version=gz_version, service_timeout=params.service_timeout
        ),
        gz_options=params.shared.gz_node_options(),
    )
    bridge.add_all(spec for source in sources for spec in source.specs)
    if not bridge.handles:
        logger.warning(
            "No bridges are running: give topic arguments, or -p config_file:=<yaml>, "
            "or bridge_names parameters (parameter_bridge -h shows the syntax)"
        )
    return bridge


def expand_if(result: ParseResult, node: Node, params: ParameterBridgeParameters) -> ParseResult:
    return expand_gz_names(result, node) if params.expand_gz_topic_names else result


if __name__ == "__main__":
    sys.exit(main())
