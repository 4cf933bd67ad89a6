"""``image_bridge``: ros_gz_image's executable on the bridge core (Gazebo->ROS camera images).

Each topic argument becomes a Gazebo->ROS ``sensor_msgs/msg/Image`` bridge of a
:class:`~ros_gz_bridge_py.core.bridge.Bridge` on the node ``ros_gz_image``; channels, QoS, lazy
switching and error counting are the bridge's. Run it as ``image_bridge`` or
``python -m ros_gz_bridge_py.app.image_bridge``; ``-h`` prints the arguments and parameters.

Beyond ros_gz_image (ros_gz issues #701, #778, #752): ``GZ_TOPIC:=ROS_TOPIC`` renames,
``config_file`` takes a parameter_bridge YAML (its Image and CameraInfo entries), ``camera_info``
bridges the camera's CameraInfo too, ``lazy`` subscribes to Gazebo only while ROS listens, and
no type needs naming for any Gazebo line: ``gz.msgs.Image`` takes Fortress's
``ignition.msgs.Image`` publishers as well (``gz_type`` stays as an override);
``expand_gz_topic_names`` puts relative Gazebo names in the node namespace, as
``parameter_bridge`` does (ros_gz issue 778), and ``max_rate`` limits every image stream.
A frame whose data is shorter than height x width x bytes per pixel, or whose pixel format has
no ROS encoding, is counted, logged (throttled) and not published. There is no image_transport: only
the raw topic is published.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Sequence

import rclpy
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ros_gz_bridge_py.app.image_bridge_args import (
    USAGE,
    ImageTopic,
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
from ros_gz_bridge_py.app.ros_arguments import ros_arguments_problem, unknown_parameters
from ros_gz_bridge_py.app.settings import (
    ImageBridgeParameters,
    Switches,
    checked_max_queued_bytes,
    checked_max_rate,
    declare_image_bridge_parameters,
    read_switches,
)
from ros_gz_bridge_py.app.startup import finish_start_up
from ros_gz_bridge_py.config import (
    TopicBridgeSpec,
    UsageError,
    expand_topic_name,
    read_yaml_file,
)
from ros_gz_bridge_py.config.gz_version import check_gz_version
from ros_gz_bridge_py.core.bridge import Bridge
from ros_gz_bridge_py.core.status import DiagnosticsPublisher, serve, start_diagnostics
from ros_gz_bridge_py.errors import ConfigError, TransportError
from ros_gz_bridge_py.ros.bridge_node import BridgeNode
from ros_gz_bridge_py.ros.python_logging import python_logging_to
from ros_gz_bridge_py.ros.runtime import apply_speed_settings
from ros_gz_bridge_py.ros.stop_signal import StopSignal

PROGRAM = "image_bridge"
NODE_NAME = "ros_gz_image"
#: Exit status for bad arguments, as ros_gz_image (``return -1``).
USAGE_EXIT = 255
#: Exit status when the Gazebo Transport side cannot be opened, as parameter_bridge's.
TRANSPORT_EXIT = 1
#: What sets the QoS of image_bridge's channels, as its explanations name it.
QOS_SETTING = "image_bridge's qos parameter (default, sensor_data or system_default)"


def bridge_specs(
    node: Node, topics: Sequence[TopicBridgeSpec], params: ImageBridgeParameters
) -> list[TopicBridgeSpec]:
    """Every bridge to create: the topic arguments, the config file's entries, camera infos.

    Problems with the ``qos`` value and the config file are logged here; what can be bridged is.
    """
    logger = node.get_logger()
    specs = list(topics)
    if params.shared.config_file:
        config = select_config_entries(read_yaml_file(params.shared.config_file))
        for warning in config.warnings:
            logger.warning(warning)
        for error in config.errors:
            logger.error(str(error))
        specs += [spec for spec in config.specs if isinstance(spec, TopicBridgeSpec)]
    if params.shared.expand_gz_topic_names:
        namespace, name = node.get_namespace(), node.get_name()
        specs = [
            dataclasses.replace(spec, gz_topic=expand_topic_name(spec.gz_topic, namespace, name))
            for spec in specs
        ]
    if params.camera_info:
        specs = list(with_camera_info(specs))
    try:
        profile = qos_profile_name(params.qos)
    except ConfigError as err:
        logger.error(str(err))
        profile = None
    return list(with_qos(specs, profile))


def declared_parameters(node: Node) -> ImageBridgeParameters | None:
    """The node's parameters, or None (logged) when one has a value of the wrong type."""
    try:
        return declare_image_bridge_parameters(node)
    except ConfigError as err:
        node.get_logger().error(str(err))
        return None


def build_bridge(
    node: Node,
    params: ImageBridgeParameters,
    topics: Sequence[ImageTopic],
    switches: Switches,
    *,
    stop: StopSignal,
    ros_args: Sequence[str],
) -> Bridge | None:
    """The running bridge, or None (logged) when the parameters leave nothing to bridge;
    ``ros_args`` are the ROS arguments, whose parameters no parameter takes are warned of."""
    logger = node.get_logger()
    for warning in switches.warnings:
        logger.warning(warning)
    try:
        gz_type = check_gz_type(params.gz_type)
        gz_version = check_gz_version(params.shared.gz_version)
    except ConfigError as err:
        logger.error(str(err))
        return None
    for warning in unknown_parameters(PROGRAM, ros_args, node):
        logger.warning(warning)
    specs = bridge_specs(node, topic_specs(topics, gz_type), params)
    if not specs:
        logger.error(
            "No image topics to bridge: give topic arguments or -p config_file:=<yaml> "
            "(image_bridge -h shows the syntax)"
        )
        return None
    max_rate, problem = checked_max_rate(params.shared)
    max_queued_bytes, queue_problem = checked_max_queued_bytes(params.shared)
    for message in (problem, queue_problem):
        if message:
            logger.error(message)
    options = params.shared.bridge_options(
        switches, gz_version=gz_version, max_rate=max_rate, max_queued_bytes=max_queued_bytes
    )
    bridge = Bridge(
        node,
        options=dataclasses.replace(options, types_fixed_by=PROGRAM, qos_setting=QOS_SETTING),
        gz_options=params.shared.gz_node_options(stop),
    )
    if bridge.add_all(specs) and not bridge.handles:
        logger.error("No image topic could be bridged (each is refused above)")
        bridge.close()
        return None
    return bridge


def run(
    topics: Sequence[ImageTopic], switches: Switches, stop: StopSignal, ros_args: Sequence[str]
) -> int:
    """Bridge until ``stop`` or rclpy shutdown; the node and bridge are closed on the way out."""
    node = BridgeNode(NODE_NAME)
    with python_logging_to(node.get_logger()):
        return _run(node, topics, switches, stop, ros_args)


def _run(
    node: BridgeNode,
    topics: Sequence[ImageTopic],
    switches: Switches,
    stop: StopSignal,
    ros_args: Sequence[str],
) -> int:
    bridge: Bridge | None = None
    diagnostics: DiagnosticsPublisher | None = None
    try:
        params = declared_parameters(node)
        if params is None:
            return USAGE_EXIT
        bridge = build_bridge(node, params, topics, switches, stop=stop, ros_args=ros_args)
        if bridge is None:
            return USAGE_EXIT
        if stop.requested:
            return 0
        diagnostics = start_diagnostics(node, bridge, params.shared.status_period)
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
        if diagnostics is not None:
            diagnostics.close()
        if bridge is not None:
            bridge.close()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def main(argv: Sequence[str] | None = None, stop: StopSignal | None = None) -> int:
    """Run the image bridge on ``argv`` (with the program name); return the exit status.

    ``stop``: SIGINT/SIGTERM handlers the entry point installed before importing us; None
    installs them here.
    """
    argv = list(sys.argv if argv is None else argv)
    ros_args, positional = split_ros_args(argv[1:])
    if wants_help(positional):
        print(USAGE, end="")
        return 0
    if len(argv) < 2:
        print(USAGE, end="", file=sys.stderr)
        return USAGE_EXIT
    problem = ros_arguments_problem(PROGRAM, [argv[0], *ros_args])
    if problem:
        print(problem, file=sys.stderr)
        return USAGE_EXIT
    try:
        topics = parse_topic_args(positional)
    except UsageError as err:
        print(f"{PROGRAM}: {err}\n\n{USAGE}", end="", file=sys.stderr)
        return USAGE_EXIT

    if stop is not None and stop.requested:
        return 0
    switches = read_switches()
    cleaned = apply_speed_settings(fastdds_profile=switches.fastdds_profile)
    rclpy.init(args=[argv[0], *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    if cleaned:
        rclpy.logging.get_logger(NODE_NAME).info(cleaned)
    if stop is not None:
        return run(topics, switches, stop, ros_args)
    with StopSignal() as own:
        return run(topics, switches, own, ros_args)


if __name__ == "__main__":
    sys.exit(main())
