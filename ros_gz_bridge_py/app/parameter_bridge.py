"""``parameter_bridge``: the main loop, the bridges made from the configuration (its sources are
read by :mod:`~.sources`), and the ``--check`` and ``--discover`` modes.

Configuration is parsed completely first (arguments, the ``config_file`` YAML, ``bridge_names``
parameters), then every bridge is created; an entry that fails is reported with its location and
skipped, the others bridge. Unlike the C++ bridge, the YAML file is read once at start (not on
the first heartbeat, and not again on every heartbeat when it fails), and it applies together
with command-line bridges.

Ours beyond C++: ``${name}`` placeholders (``NAME=VALUE`` arguments and the ``placeholders``
parameter), YAML entries that discovery completes and ``auto_bridge`` (both followed by
``core/discovered.py``), ``--discover`` (``discover.py``), ``max_rate``, and
``expand_gz_topic_names`` applied to the command line too.
"""

from __future__ import annotations

import contextlib
import functools
import sys
from collections.abc import Sequence

import rclpy
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from ros_gz_bridge_py.app import discover
from ros_gz_bridge_py.app.check import DEFAULT_SECONDS as DEFAULT_CHECK_SECONDS
from ros_gz_bridge_py.app.check import Sides, run_check
from ros_gz_bridge_py.app.one_cpu import OneCpu, start_one_cpu
from ros_gz_bridge_py.app.ros_arguments import ros_arguments_problem, unknown_parameters
from ros_gz_bridge_py.app.settings import (
    ParameterBridgeParameters,
    Switches,
    checked_max_queued_bytes,
    checked_max_rate,
    declare_parameter_bridge_parameters,
    read_switches,
)
from ros_gz_bridge_py.app.sources import (
    bridge_parameter_problem,
    collect_sources,
    discovery_rules,
    gz_subscriptions,
    placeholder_values,
)
from ros_gz_bridge_py.app.startup import finish_start_up
from ros_gz_bridge_py.config import (
    USAGE,
    BridgeSpec,
    ParseResult,
    TopicBridgeSpec,
    UsageError,
    parse_cli_args,
    templates,
)
from ros_gz_bridge_py.config.cli import cli_placeholders
from ros_gz_bridge_py.config.discovered import AutoBridgeRules
from ros_gz_bridge_py.config.gz_version import check_gz_version
from ros_gz_bridge_py.config.patterns import TopicPattern
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.core.bridge import Bridge
from ros_gz_bridge_py.core.discovered import DiscoveredBridges, ros_publishers
from ros_gz_bridge_py.core.discovery_plan import Plan, Sighting, plan, ros_names_to_read, sightings
from ros_gz_bridge_py.core.explain import gazebo_name
from ros_gz_bridge_py.core.status import DiagnosticsPublisher, serve, start_diagnostics
from ros_gz_bridge_py.errors import ConfigError, TransportError
from ros_gz_bridge_py.ros.bridge_node import BridgeNode
from ros_gz_bridge_py.ros.python_logging import python_logging_to
from ros_gz_bridge_py.ros.runtime import apply_speed_settings, make_executor
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import GzNode, create_gz_node
from ros_gz_bridge_py.transport.settings import DEFAULT_HWM, planned_rcvhwm

PROGRAM = "parameter_bridge"
NODE_NAME = "ros_gz_bridge"
#: ``parameter_bridge --check [SECONDS]``: report on the entries instead of bridging them.
CHECK_OPTION = "--check"
#: ``parameter_bridge --discover [SECONDS]``: print the YAML of what discovery shows.
DISCOVER_OPTION = "--discover"
#: Exit status for bad arguments, as the C++ bridge (``return -1``).
USAGE_EXIT = 255
#: Exit status when the Gazebo Transport side cannot be opened (a Zenoh router not there).
TRANSPORT_EXIT = 1
#: How many YAML entries completed by discovery the start-up line names.
SHOWN_ENTRIES = 3


def main(argv: Sequence[str] | None = None, stop: StopSignal | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = argv[1:]
    problem = ros_arguments_problem(PROGRAM, argv)
    if problem:
        print(problem, file=sys.stderr)
        return USAGE_EXIT
    positional = remove_ros_args(argv)[1:]
    if any(arg in ("-h", "--help") for arg in positional):
        print(USAGE)
        return 0
    if not args:
        print(USAGE)
        return USAGE_EXIT
    try:
        check_seconds, positional = split_check_option(positional)
        discover_seconds, positional = split_seconds_option(
            positional, DISCOVER_OPTION, discover.DEFAULT_SECONDS
        )
        cli_values = cli_placeholders(positional)
        parse_cli_args([arg for arg in positional if not templates.names_in([arg])])
    except ConfigError as err:
        print(USAGE)
        print(f"{PROGRAM}: {err}", file=sys.stderr)
        return USAGE_EXIT

    if stop is not None and stop.requested:
        return 0
    switches = read_switches()
    cleaned = apply_speed_settings(fastdds_profile=switches.fastdds_profile)
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    if cleaned:
        rclpy.logging.get_logger(NODE_NAME).info(cleaned)
    with contextlib.ExitStack() as scope:
        if stop is None:
            stop = scope.enter_context(StopSignal())
        node = BridgeNode(NODE_NAME)
        scope.enter_context(python_logging_to(node.get_logger()))
        bridge: Bridge | None = None
        diagnostics: DiagnosticsPublisher | None = None
        discovered: DiscoveredBridges | None = None
        one_cpu: OneCpu | None = None
        try:
            try:
                params = declare_parameter_bridge_parameters(node)
            except ConfigError as err:  # a parameter of the wrong type
                node.get_logger().error(str(err))
                return USAGE_EXIT
            bridges = functools.partial(bridge_parameter_problem, bridge_names=params.bridge_names)
            for warning in unknown_parameters(PROGRAM, argv, node, bridges):
                node.get_logger().warning(warning)
            try:
                values = placeholder_values(params, cli_values)
                cli = parse_cli_args(positional, values)
            except ConfigError as err:  # a placeholder of an argument without a value
                print(USAGE)
                print(f"{PROGRAM}: {err}", file=sys.stderr)
                return USAGE_EXIT
            if stop.requested:
                return 0
            if check_seconds is not None:
                finish_start_up(node)
                return check(node, cli, params, switches, check_seconds, values=values, stop=stop)
            if discover_seconds is not None:
                finish_start_up(node)
                return discover_yaml(node, cli, params, discover_seconds, values, stop=stop)
            bridge, discovered = build_bridge(node, cli, params, switches, values, stop=stop)
            diagnostics = start_diagnostics(node, bridge, params.shared.status_period)
            one_cpu = start_one_cpu(node, bridge.carries_bulk, switches.one_cpu)
            finish_start_up(node)
            serve(
                node,
                bridge,
                stop,
                events_executor=switches.events_executor,
                dds_event_batch=switches.dds_event_batch,
            )
        except TransportError as err:
            if stop.requested:  # Ctrl-C while the node started (a Zenoh client's wait)
                return 0
            node.get_logger().error(str(err))
            return TRANSPORT_EXIT
        finally:
            if one_cpu is not None:
                one_cpu.close()
            if diagnostics is not None:
                diagnostics.close()
            if discovered is not None:
                discovered.close()
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
    return split_seconds_option(args, CHECK_OPTION, DEFAULT_CHECK_SECONDS)


def split_seconds_option(
    args: Sequence[str], option: str, default: float
) -> tuple[float | None, list[str]]:
    """(``option``'s seconds or None, the other arguments): ``option [SECONDS]`` anywhere.

    Raises:
        UsageError: the seconds are not a finite number > 0.
    """
    rest = list(args)
    if option not in rest:
        return None, rest
    index = rest.index(option)
    del rest[index]
    seconds = default
    candidate = rest[index] if index < len(rest) else ""
    if (
        candidate
        and not candidate.startswith("/")
        and "@" not in candidate
        and "=" not in candidate
    ):
        text = rest.pop(index)
        try:
            seconds = float(text)
        except ValueError:
            seconds = -1.0
        if not 0 < seconds < float("inf"):  # nan and inf too: inf would never end
            msg = f"{option} takes a number of seconds > 0 to listen for (finite), not {text!r}"
            raise UsageError(msg, f"argument '{option} {text}'")
    return seconds, rest


def check(
    node: Node,
    cli: ParseResult,
    params: ParameterBridgeParameters,
    switches: Switches,
    seconds: float,
    *,
    values: templates.Placeholders,
    stop: StopSignal,
) -> int:
    """``--check``: report on every entry without bridging (:mod:`ros_gz_bridge_py.app.check`);
    ``stop`` ends its listening early."""
    sources = collect_sources(node, cli, params, values)
    specs = [spec for source in sources for spec in source.specs]
    errors = sum(len(source.errors) for source in sources)
    patterns = [pattern for source in sources for pattern in source.patterns]
    rules = discovery_rules(node, params, enabled=params.auto_bridge)
    if not specs and not errors and not patterns and not rules.enabled:
        print(
            "parameter_bridge --check: no entries to check (give topics, config_file or "
            "-p auto_bridge:=true)"
        )
        return USAGE_EXIT
    executor = make_executor(events=switches.events_executor)
    executor.add_node(node)
    with create_gz_node(params.shared.gz_node_options(stop)) as gz_node:

        def discovered() -> list[TopicBridgeSpec]:
            if not patterns and not rules.enabled:
                return []
            _, wanted = discovered_plan(node, gz_node, specs, patterns, rules)
            for topic, why in wanted.skipped.items():
                print(f"Discovered {topic}: not bridged: {why}")
            return list(wanted.specs.values())

        for pattern in patterns:
            print(
                f"{pattern.source}: completed by Gazebo discovery (a type left out, or a "
                "wildcard): checked as the topics it takes"
            )
        sides = Sides(node, gz_node, default_registry())
        status = run_check(
            sides, specs, seconds, out=sys.stdout, spin_once=executor.spin_once,
            discovered=discovered, stop=stop,
        )  # fmt: skip
    if errors:
        print(f"{errors} configuration entries could not be read (see the errors above)")
    return 1 if errors else status


def discover_yaml(
    node: Node,
    cli: ParseResult,
    params: ParameterBridgeParameters,
    seconds: float,
    values: templates.Placeholders,
    *,
    stop: StopSignal,
) -> int:
    """``--discover``: print the YAML of what discovered bridging would bridge (``discover.py``);
    1 when a configuration entry could not be read. ``stop`` ends its listening early: the YAML
    then holds what was heard until then."""
    sources = collect_sources(node, cli, params, values)
    explicit = [spec for source in sources for spec in source.specs]
    patterns = [pattern for source in sources for pattern in source.patterns]
    rules = discovery_rules(node, params, enabled=True)
    with create_gz_node(params.shared.gz_node_options(stop)) as gz_node:
        node.get_logger().info(f"Listening to Gazebo discovery for {seconds:g} s ...")
        if discover.listen(seconds / 2, stop=stop):
            gz_node.ask_subscribers()  # gz-transport 13+ list their subscriptions with types
            discover.listen(seconds / 2, stop=stop)
        found, wanted = discovered_plan(node, gz_node, explicit, patterns, rules)
        listening = gz_node.listening()
    for topic, why in wanted.skipped.items():
        node.get_logger().info(f"Not bridging Gazebo {topic}: {why}")
    for topic, note in wanted.notes.items():
        node.get_logger().warning(f"Gazebo {topic}: {note}")
    specs = list(wanted.specs.values())
    discover.write_yaml(
        specs, discover.header_lines(seconds, listening, len(found), specs), sys.stdout
    )
    return 1 if any(source.errors for source in sources) else 0


def discovered_plan(
    node: Node,
    gz_node: GzNode,
    explicit: Sequence[BridgeSpec],
    patterns: Sequence[TopicPattern],
    rules: AutoBridgeRules,
) -> tuple[dict[str, Sighting], Plan]:
    """What discovered bridging would bridge now, beside the ``explicit`` entries (the
    sightings of the partition, and the plan)."""
    found = sightings(gz_node.graph(), gz_node.partition, gz_node.peer_spelling)
    explicit_names = frozenset(
        gazebo_name(gz_node, spec.gz_topic)[1]
        for spec in explicit
        if isinstance(spec, TopicBridgeSpec)
    )
    ros = ros_publishers(node, ros_names_to_read(found), {(node.get_name(), node.get_namespace())})
    wanted = plan(
        found, patterns=patterns, rules=rules, registry=default_registry(),
        explicit=explicit_names, ros_publishers=ros,
    )  # fmt: skip
    return found, wanted


def build_bridge(
    node: Node,
    cli: ParseResult,
    params: ParameterBridgeParameters,
    switches: Switches,
    values: templates.Placeholders,
    *,
    stop: StopSignal,
) -> tuple[Bridge, DiscoveredBridges | None]:
    """Collect every configuration source, report its problems, and create the bridges; and
    what follows discovery, when entries or ``auto_bridge`` ask for it."""
    logger = node.get_logger()
    for warning in switches.warnings:
        logger.warning(warning)
    sources = collect_sources(node, cli, params, values)
    try:
        gz_version = check_gz_version(params.shared.gz_version)
    except ConfigError as err:
        logger.error(str(err))
        gz_version = ""
    max_rate, problem = checked_max_rate(params.shared)
    max_queued_bytes, queue_problem = checked_max_queued_bytes(params.shared)
    for message in (problem, queue_problem):
        if message:
            logger.error(message)
    gz_options = params.shared.gz_node_options(stop, gz_subscriptions(sources))
    bridge = Bridge(
        node,
        options=params.shared.bridge_options(
            switches,
            gz_version=gz_version,
            service_timeout=params.service_timeout,
            max_rate=max_rate,
            max_queued_bytes=max_queued_bytes,
        ),
        gz_options=gz_options,
    )
    settings = bridge.gz_node.settings
    if (gz_options.implementation or settings.implementation) == "zeromq" and (
        planned_rcvhwm(gz_options.planned_subscriptions) < DEFAULT_HWM
    ):
        logger.info(
            f"{gz_options.planned_subscriptions} Gazebo topics: the ZeroMQ receive queue of each "
            f"topic with a socket of its own holds {settings.rcvhwm} messages, that of the "
            f"socket the native channels of small messages share {settings.shared_rcvhwm} per "
            'publisher (GZ_TRANSPORT_RCVHWM sets both; docs/many-topics.md, "A fleet\'s memory")'
        )
    failures = bridge.add_all(spec for source in sources for spec in source.specs)
    unread = sum(len(source.errors) for source in sources)  # a file not read, an entry refused
    patterns: list[TopicPattern] = [p for source in sources for p in source.patterns]
    rules = discovery_rules(node, params, enabled=params.auto_bridge)
    discovered = None
    if patterns or rules.enabled:
        discovered = DiscoveredBridges(bridge, patterns=patterns, rules=rules)
        what = ["auto_bridge"] if rules.enabled else []
        what += [_completed_entries(patterns)] if patterns else []
        logger.info(f"Following Gazebo discovery: {' and '.join(what)}")
    elif not bridge.handles and (failures or unread):
        logger.warning(
            f"No bridges are running: no entry could be bridged ({len(failures) + unread} "
            "failed; the errors above say why and what to write)"
        )
    elif not bridge.handles:
        logger.warning(
            "No bridges are running: give topic arguments, or -p config_file:=<yaml>, "
            "or bridge_names parameters, or -p auto_bridge:=true "
            "(parameter_bridge -h shows the syntax)"
        )
    return bridge, discovered


def _completed_entries(patterns: Sequence[TopicPattern]) -> str:
    """The YAML entries discovery completes, named (the first few)."""
    named = ", ".join(pattern.source for pattern in patterns[:SHOWN_ENTRIES])
    more = f" and {len(patterns) - SHOWN_ENTRIES} more" if len(patterns) > SHOWN_ENTRIES else ""
    count = "1 YAML entry" if len(patterns) == 1 else f"{len(patterns)} YAML entries"
    return f"{count} completed by discovery ({named}{more})"


if __name__ == "__main__":
    sys.exit(main())
