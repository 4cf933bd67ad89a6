"""``RosGzBridge``: ros_gz_bridge's launch action (Jazzy), starting this bridge's ``bridge_node``.

The same keyword arguments as ``ros_gz_bridge.actions.RosGzBridge``, and the same frontend
attributes and ``<topic>`` / ``<service>`` children under the tag ``ros_gz_bridge_py``
(registered through the ``launch.frontend.launch_extension`` entry point; ros_gz's tag
``ros_gz_bridge`` is left to ros_gz). What the arguments start is decided in
:mod:`ros_gz_bridge_py.app.bridge_launch`; this module only performs substitutions and builds
the ``launch_ros`` ``Node``. ``launch_ros`` is imported when the action runs, so that loading
the entry point (which launch does for every XML or YAML file) needs only ``launch``.
"""

from __future__ import annotations

from typing import Any

import launch.logging
from launch.action import Action
from launch.frontend import Entity, Parser, expose_action
from launch.launch_context import LaunchContext
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

from ros_gz_bridge_py.app.bridge_launch import (
    LAUNCH_ARGUMENTS,
    BridgeLaunch,
    bridge_process,
    extra_parameter_dicts,
    find_bridge_node,
)

TAG = "ros_gz_bridge_py"
_DEFAULTS = BridgeLaunch(bridge_name="")
#: The attributes of the tag: the launch file's arguments (``bridge_name`` must be given).
ATTRIBUTES = tuple(argument.name for argument in LAUNCH_ARGUMENTS)
#: ``<topic>`` children: the attributes they must have, and those they may have (a
#: ``bridges.<name>.<key>`` parameter each).
TOPIC_REQUIRED = ("ros_topic_name", "ros_type_name", "gz_topic_name", "gz_type_name")
TOPIC_OPTIONAL = (
    "direction",
    "lazy",
    "publisher_queue",
    "subscriber_queue",
    "qos_profile",
    "frame_id",
    "max_rate",
)
SERVICE_REQUIRED = ("service_name", "ros_type_name", "gz_req_type_name", "gz_rep_type_name")


def _substitutions(value: Any) -> Any:
    """A boolean as it is, anything else as launch's list of substitutions."""
    return value if isinstance(value, bool) else normalize_to_list_of_substitutions(value)


def _performed(context: LaunchContext, value: Any) -> Any:
    return value if isinstance(value, bool) else perform_substitutions(context, value)


@expose_action(TAG)
class RosGzBridge(Action):
    """Start this bridge's ``bridge_node`` as ros_gz_bridge's ``RosGzBridge`` would start its
    own (with composition asked for, as a process all the same, said in one line)."""

    def __init__(
        self,
        *,
        bridge_name: Any,
        config_file: Any = _DEFAULTS.config_file,
        container_name: Any = _DEFAULTS.container_name,
        create_own_container: Any = _DEFAULTS.create_own_container,
        namespace: Any = _DEFAULTS.namespace,
        use_composition: Any = _DEFAULTS.use_composition,
        use_respawn: Any = _DEFAULTS.use_respawn,
        log_level: Any = _DEFAULTS.log_level,
        bridge_params: Any = _DEFAULTS.bridge_params,
        extra_bridge_params: Any = None,
        **kwargs: Any,
    ) -> None:
        """Arguments as ros_gz_bridge's: text, substitutions, or (the switches) booleans;
        ``extra_bridge_params`` a dict of node parameters (or a list of dicts)."""
        super().__init__(**kwargs)
        given = {
            "bridge_name": bridge_name,
            "config_file": config_file,
            "container_name": container_name,
            "create_own_container": create_own_container,
            "namespace": namespace,
            "use_composition": use_composition,
            "use_respawn": use_respawn,
            "log_level": log_level,
            "bridge_params": bridge_params,
        }
        self.__arguments = {name: _substitutions(value) for name, value in given.items()}
        self.__extra = extra_parameter_dicts(extra_bridge_params)

    @classmethod
    def parse(cls, entity: Entity, parser: Parser) -> tuple[type[RosGzBridge], dict[str, Any]]:
        """The tag's attributes, and its ``<topic>`` and ``<service>`` children as
        ``bridges.bridge_<n>.*`` parameters (``bridge_names`` listing them)."""
        _, kwargs = super().parse(entity, parser)
        for name in ATTRIBUTES:
            text = entity.get_attr(name, data_type=str, optional=name != "bridge_name")
            if text is not None:
                kwargs[name] = parser.parse_substitution(text)
        bridges: dict[str, dict[str, Any]] = {}
        for tag, required, optional in (
            ("topic", TOPIC_REQUIRED, TOPIC_OPTIONAL),
            ("service", SERVICE_REQUIRED, ()),
        ):
            for child in entity.get_attr(tag, data_type=list[Entity], optional=True) or ():
                bridge = {}
                for key in (*required, *optional):
                    text = child.get_attr(key, data_type=str, optional=key not in required)
                    if text is not None:
                        bridge[key] = parser.parse_substitution(text)
                child.assert_entity_completely_parsed()
                bridges[f"bridge_{len(bridges)}"] = bridge
        if bridges:
            kwargs["extra_bridge_params"] = {"bridges": bridges, "bridge_names": sorted(bridges)}
        return cls, kwargs

    def execute(self, context: LaunchContext) -> list[Action]:
        """The ``bridge_node`` process."""
        from launch_ros.actions import Node  # noqa: PLC0415 - see the module docstring
        from launch_ros.parameter_descriptions import ParameterValue  # noqa: PLC0415

        performed = {name: _performed(context, value) for name, value in self.__arguments.items()}
        process = bridge_process(BridgeLaunch(**performed), find_bridge_node())
        if process.note:
            launch.logging.get_logger(TAG).warning(process.note)
        config = {"config_file": ParameterValue(process.config_file, value_type=str)}
        return [
            Node(
                executable=process.executable,
                name=process.node_name,
                namespace=process.namespace,
                output="screen",
                respawn=process.respawn,
                respawn_delay=process.respawn_delay,
                parameters=[{**config, **process.bridge_params}, *self.__extra],
                arguments=list(process.arguments),
            )
        ]
