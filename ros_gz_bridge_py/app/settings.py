"""Every setting of the executables, read once at start, into frozen dataclasses.

``parameter_bridge`` and ``image_bridge`` read the environment here and nowhere else: the
``ROS_GZ_BRIDGE_*`` switches (:func:`read_switches`) and ``GZ_VERSION``, the default of the
``gz_version`` parameter. Their node parameters are declared here too, the ones they share
(:class:`SharedParameters`) with one name, type and default. The executables then hand the
library :class:`~ros_gz_bridge_py.core.bridge.Bridge` its :class:`BridgeOptions` and the runtime
helpers plain arguments (docs/configuration.md: "Node parameters", "Speed settings and switches").

One rule per kind of value: a switch is off when set to ``off``, ``0``, ``false`` or ``no``; a
choice compares its value case-blind; an integer that is not one is reported (variable, value,
fallback) and the default is used.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.parameter import Parameter

from ros_gz_bridge_py.config.gz_version import GZ_VERSION_ENV
from ros_gz_bridge_py.config.model import as_rate
from ros_gz_bridge_py.core.options import BULK_THREAD_NICE, BridgeOptions
from ros_gz_bridge_py.core.services import DEFAULT_TIMEOUT
from ros_gz_bridge_py.errors import ConfigError
from ros_gz_bridge_py.transport import BACKENDS, NodeOptions
from ros_gz_bridge_py.transport.delivery import MAX_QUEUED_BYTES

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from ros_gz_bridge_py.ros.stop_signal import StopSignal

#: Values (any case, surrounding spaces ignored) that turn a switch off.
OFF_VALUES = frozenset({"off", "0", "false", "no"})

#: ``single``: rclpy's SingleThreadedExecutor instead of the EventsExecutor.
EXECUTOR_ENV = "ROS_GZ_BRIDGE_EXECUTOR"
#: A switch: off keeps Fast DDS's own transports (no profile of ours).
FASTDDS_PROFILE_ENV = "ROS_GZ_BRIDGE_FASTDDS_PROFILE"
#: A switch: off sends images and point clouds through protobuf and rclpy's message objects.
BULK_PATH_ENV = "ROS_GZ_BRIDGE_BULK_PATH"
#: ``rclpy``: the bulk path publishes through rclpy (GIL held) instead of through rcl.
SERIALIZED_PUBLISH_ENV = "ROS_GZ_BRIDGE_SERIALIZED_PUBLISH"
#: An integer: the nice offset of bulk-path delivery threads (0: none).
BULK_NICE_ENV = "ROS_GZ_BRIDGE_BULK_NICE"
#: A switch: off makes ROS->Gazebo channels take rclpy's message objects.
LIGHT_READ_ENV = "ROS_GZ_BRIDGE_LIGHT_READ"
#: A switch: off makes Gazebo->ROS channels publish rclpy's message objects through rclpy.
CDR_WRITE_ENV = "ROS_GZ_BRIDGE_CDR_WRITE"
#: A switch: off keeps every channel on the Python path (no native data plane).
NATIVE_ENV = "ROS_GZ_BRIDGE_NATIVE"
#: A switch: off leaves Fast DDS's event threads at normal scheduling (not SCHED_BATCH).
DDS_EVENT_BATCH_ENV = "ROS_GZ_BRIDGE_DDS_EVENT_BATCH"
#: A switch: off leaves ``parameter_bridge``'s threads on every CPU (no :mod:`~.one_cpu`).
ONE_CPU_ENV = "ROS_GZ_BRIDGE_ONE_CPU"
#: gz-transport's choice of implementation (``zeromq`` when unset), read by the transport.
TRANSPORT_IMPLEMENTATION_ENV = "GZ_TRANSPORT_IMPLEMENTATION"


#: The switches that are :class:`BridgeOptions` of the same names (how messages travel).
MESSAGE_PATH_SWITCHES = (
    "bulk_path",
    "rcl_serialized_publish",
    "bulk_nice",
    "light_read",
    "cdr_write",
    "native",
)


@dataclass(frozen=True)
class Switches:
    """The ``ROS_GZ_BRIDGE_*`` environment switches; the defaults are the fast settings."""

    #: False with ``ROS_GZ_BRIDGE_EXECUTOR=single``.
    events_executor: bool = True
    #: False with ``ROS_GZ_BRIDGE_FASTDDS_PROFILE=off``.
    fastdds_profile: bool = True
    #: False with ``ROS_GZ_BRIDGE_BULK_PATH=off``.
    bulk_path: bool = True
    #: False with ``ROS_GZ_BRIDGE_SERIALIZED_PUBLISH=rclpy``.
    rcl_serialized_publish: bool = True
    #: ``ROS_GZ_BRIDGE_BULK_NICE``.
    bulk_nice: int = BULK_THREAD_NICE
    #: False with ``ROS_GZ_BRIDGE_LIGHT_READ=off``.
    light_read: bool = True
    #: False with ``ROS_GZ_BRIDGE_CDR_WRITE=off``.
    cdr_write: bool = True
    #: False with ``ROS_GZ_BRIDGE_NATIVE=off``.
    native: bool = True
    #: False with ``ROS_GZ_BRIDGE_DDS_EVENT_BATCH=off``.
    dds_event_batch: bool = True
    #: False with ``ROS_GZ_BRIDGE_ONE_CPU=off``.
    one_cpu: bool = True
    #: What was wrong with a value, one sentence each: the executables log them once their
    #: node exists (the switches are read before ``rclpy.init``).
    warnings: tuple[str, ...] = ()


def switched_off(name: str, env: Mapping[str, str]) -> bool:
    """True when the variable ``name`` of ``env`` says off."""
    return env.get(name, "").strip().lower() in OFF_VALUES


def _chosen(name: str, value: str, env: Mapping[str, str]) -> bool:
    """True when the variable ``name`` of ``env`` is ``value`` (any case, spaces ignored)."""
    return env.get(name, "").strip().lower() == value


def _integer(name: str, default: int, hint: str, env: Mapping[str, str]) -> tuple[int, str]:
    """(the integer in the variable ``name``, or ``default``; a warning when the value is not
    an integer, else ''). Unset or blank is ``default`` without a warning."""
    text = env.get(name, "").strip()
    if not text:
        return default, ""
    try:
        return int(text), ""
    except ValueError:
        return default, f"{name}={text!r} is not an integer; using {default} ({hint})"


def read_switches(env: Mapping[str, str] | None = None) -> Switches:
    """The switches of ``env`` (default: the process's environment)."""
    env = os.environ if env is None else env
    bulk_nice, nice_warning = _integer(
        BULK_NICE_ENV,
        BULK_THREAD_NICE,
        "set a whole number, 0 to keep image threads at normal priority",
        env,
    )
    return Switches(
        events_executor=not _chosen(EXECUTOR_ENV, "single", env),
        fastdds_profile=not switched_off(FASTDDS_PROFILE_ENV, env),
        bulk_path=not switched_off(BULK_PATH_ENV, env),
        rcl_serialized_publish=not _chosen(SERIALIZED_PUBLISH_ENV, "rclpy", env),
        bulk_nice=bulk_nice,
        light_read=not switched_off(LIGHT_READ_ENV, env),
        cdr_write=not switched_off(CDR_WRITE_ENV, env),
        native=not switched_off(NATIVE_ENV, env),
        dds_event_batch=not switched_off(DDS_EVENT_BATCH_ENV, env),
        one_cpu=not switched_off(ONE_CPU_ENV, env),
        warnings=(nice_warning,) if nice_warning else (),
    )


@dataclass(frozen=True)
class SharedParameters:
    """The node parameters both executables declare (the C++ bridge's, and ours)."""

    config_file: str = ""
    lazy: bool = False
    #: Milliseconds between two lazy re-checks, at least 1.
    subscription_heartbeat: int = 1000
    override_timestamps_with_wall_time: bool = False
    override_frame_id: str = ""
    #: Ours: "zeromq" or "zenoh"; empty = GZ_TRANSPORT_IMPLEMENTATION, as gz-transport does.
    gz_transport_implementation: str = ""
    #: Ours: the simulator's Gazebo line, when it must be said (only "garden" matters);
    #: declared with ``GZ_VERSION`` as its default.
    gz_version: str = ""
    #: Apply the node namespace to Gazebo names (C++: YAML and ``bridges.*`` only; ours: the
    #: command line and ``image_bridge`` too).
    expand_gz_topic_names: bool = False
    #: Ours: messages per second every channel passes at most unless its entry says (0: no
    #: limit). Declared with any type (``10`` or ``10.0``); :func:`checked_max_rate` reads it.
    max_rate: object = 0.0
    #: Ours: payload bytes each Gazebo->ROS channel's queue holds at most (beyond its count);
    #: :func:`checked_max_queued_bytes` reads it.
    max_queued_bytes: int = MAX_QUEUED_BYTES
    #: Ours: seconds between two /diagnostics status messages (0 = none). Any type may be
    #: given; ``start_diagnostics`` takes an int or a float and reports anything else.
    status_period: object = 0.0

    def gz_node_options(self, stop: StopSignal, planned_subscriptions: int = 0) -> NodeOptions:
        """The node's options; ``stop`` (the executable's) can end its start."""
        return NodeOptions(
            implementation=self.gz_transport_implementation or None,
            planned_subscriptions=planned_subscriptions,
            stop_requested=lambda: stop.requested,
        )

    def bridge_options(
        self,
        switches: Switches,
        *,
        gz_version: str,
        service_timeout: float = DEFAULT_TIMEOUT,
        max_rate: float = 0.0,
        max_queued_bytes: int = MAX_QUEUED_BYTES,
    ) -> BridgeOptions:
        """The bridge's options: these parameters, ``switches``, and ``gz_version`` as checked
        by :func:`~ros_gz_bridge_py.config.gz_version.check_gz_version`."""
        return BridgeOptions(
            lazy=self.lazy,
            heartbeat=self.subscription_heartbeat / 1000.0,
            override_timestamps_with_wall_time=self.override_timestamps_with_wall_time,
            override_frame_id=self.override_frame_id,
            service_timeout=service_timeout,
            **{name: getattr(switches, name) for name in MESSAGE_PATH_SWITCHES},
            gz_version=gz_version,
            max_rate=max_rate,
            max_queued_bytes=max_queued_bytes,
        )


@dataclass(frozen=True)
class ParameterBridgeParameters:
    """``parameter_bridge``'s node parameters."""

    shared: SharedParameters
    #: Ours: seconds a ROS service call waits for Gazebo before answering success=false;
    #: declared with any type (``10`` or ``10.0``) and checked by :func:`checked_service_timeout`.
    service_timeout: float = DEFAULT_TIMEOUT
    #: The ``bridges.<name>.*`` groups to read (a string array parameter with no default).
    bridge_names: tuple[str, ...] = ()
    #: Ours: bridge every Gazebo topic discovery shows (docs/many-topics.md, "Discovered bridging").
    auto_bridge: bool = False
    #: Ours: regular expressions on Gazebo names: only matching topics are auto-bridged
    #: (empty: all), and none that ``auto_bridge_deny`` matches (string arrays).
    auto_bridge_allow: tuple[str, ...] = ()
    auto_bridge_deny: tuple[str, ...] = ()
    #: Ours: ``NAME=VALUE`` items, the values of ``${NAME}`` in the YAML and arguments.
    placeholders: tuple[str, ...] = ()


@dataclass(frozen=True)
class ImageBridgeParameters:
    """``image_bridge``'s node parameters: the shared ones and ros_gz_image's own."""

    shared: SharedParameters
    qos: str = "default"
    camera_info: bool = False
    gz_type: str = "gz.msgs.Image"


_Parameters = TypeVar("_Parameters", bound="DataclassInstance")

#: How each parameter type is written on the command line, for the fix of a wrong one.
_WRITTEN_AS = {
    Parameter.Type.BOOL: "true or false",
    Parameter.Type.INTEGER: "an integer",
    Parameter.Type.DOUBLE: "a number",
    Parameter.Type.STRING: "a string",
    Parameter.Type.STRING_ARRAY: "a list of strings, such as ['a', 'b']",
}


#: Parameters are read once, at start: a set at run time is refused ("Trying to set a read-only
#: parameter"), not accepted and ignored; ``ros2 param describe`` says why.
READ_AT_START = "read once, at start: restart the bridge with the new value to change it"


def read_only(*, dynamic_typing: bool = False) -> ParameterDescriptor:
    return ParameterDescriptor(
        read_only=True, dynamic_typing=dynamic_typing, description=READ_AT_START
    )


def _declare(
    node: Any, name: str, default: object, descriptor: ParameterDescriptor | None = None
) -> Any:
    """``node.declare_parameter(...).value``; a value given of another type than the
    parameter's is a :class:`ConfigError` naming it and the fix (rclpy raises
    InvalidParameterTypeException, which ended the process with a traceback).

    Raises:
        ConfigError: the value given for ``name`` has the wrong type.
    """
    try:
        return node.declare_parameter(name, default, descriptor or read_only()).value
    except InvalidParameterTypeException as err:
        said = str(err.args[0]).removesuffix(f": {name}")  # "Trying to set parameter ..."
        expected = (
            default if isinstance(default, Parameter.Type)
            else Parameter.Type.from_parameter_value(default)
        )  # fmt: skip
        wanted = _WRITTEN_AS.get(expected, expected.name.lower())
        msg = f"parameter {name} has the wrong type ({said}); give it as {wanted}, or leave it out"
        raise ConfigError(msg) from None


def _declare_strings(node: Any, name: str) -> tuple[str, ...]:
    """A list-of-strings parameter, an empty list unless given. rclpy takes an empty list for a
    byte array, so it is declared with dynamic typing and checked here: declared with its type
    alone it had no value, and one parameter without a value empties every answer of the
    node's get_parameters service (``ros2 param dump`` printed nothing).

    Raises:
        ConfigError: the value given is not a list of strings.
    """
    value = _declare(node, name, [], read_only(dynamic_typing=True))
    if value is None or (
        isinstance(value, list | tuple) and all(isinstance(v, str) for v in value)
    ):
        return tuple(value or ())
    given = node.get_parameter(name).type_.name
    said = f"Trying to set parameter '{name}' to '{value}' of type '{given}', expecting a list"
    wanted = _WRITTEN_AS[Parameter.Type.STRING_ARRAY]
    msg = f"parameter {name} has the wrong type ({said}); give it as {wanted}, or leave it out"
    raise ConfigError(msg)


def _declare_fields(node: Any, defaults: _Parameters, skip: Collection[str]) -> _Parameters:
    """Declare a parameter per field of ``defaults`` but those in ``skip``, each defaulting to
    its value (which sets its type); ``defaults`` with the declared values."""
    values = {
        field.name: _declare(node, field.name, getattr(defaults, field.name))
        for field in dataclasses.fields(defaults)
        if field.name not in skip
    }
    return dataclasses.replace(defaults, **values)


def declare_shared_parameters(node: Any, env: Mapping[str, str] | None = None) -> SharedParameters:
    """Declare the shared parameters on ``node``; ``gz_version`` defaults to ``GZ_VERSION`` of
    ``env`` (default: the process's environment)."""
    env = os.environ if env is None else env
    defaults = SharedParameters(gz_version=env.get(GZ_VERSION_ENV, ""))
    declared = _declare_fields(node, defaults, ("max_rate", "status_period"))
    check_heartbeat(declared.subscription_heartbeat)
    check_transport_implementation(declared.gz_transport_implementation, env)
    any_type = read_only(dynamic_typing=True)
    max_rate = _declare(node, "max_rate", defaults.max_rate, any_type)
    period = _declare(node, "status_period", defaults.status_period, any_type)
    return dataclasses.replace(declared, max_rate=max_rate, status_period=period)


def declare_parameter_bridge_parameters(
    node: Any, env: Mapping[str, str] | None = None
) -> ParameterBridgeParameters:
    """Declare ``parameter_bridge``'s parameters on ``node`` and return their values."""
    arrays = ("bridge_names", "auto_bridge_allow", "auto_bridge_deny", "placeholders")
    declared = _declare_fields(
        node,
        ParameterBridgeParameters(declare_shared_parameters(node, env)),
        ("shared", "service_timeout", *arrays),
    )
    lists: dict[str, Any] = {name: _declare_strings(node, name) for name in arrays}
    any_type = read_only(dynamic_typing=True)
    timeout = _declare(node, "service_timeout", declared.service_timeout, any_type)
    return dataclasses.replace(declared, service_timeout=checked_service_timeout(timeout), **lists)


def check_heartbeat(milliseconds: int) -> None:
    """Refuse a heartbeat timer period below 1 ms (rclcpp refuses a negative period, and one
    of 0 would re-check without pause).

    Raises:
        ConfigError: naming the parameter and its range.
    """
    if milliseconds < 1:
        msg = (
            f"parameter subscription_heartbeat is {milliseconds}; it must be an integer >= 1 "
            "(milliseconds between lazy re-checks; default 1000)"
        )
        raise ConfigError(msg)


def checked_service_timeout(value: object) -> float:
    """``value`` as the seconds a service call waits: an integer or a decimal number > 0.

    Raises:
        ConfigError: anything else (a string, a bool, 0, a negative or infinite number).
    """
    if isinstance(value, int | float) and not isinstance(value, bool) and 0 < value < math.inf:
        return float(value)
    msg = (
        f"parameter service_timeout must be a number of seconds > 0, such as 5 or 2.5, "
        f"got {value!r}"
    )
    raise ConfigError(msg)


def check_transport_implementation(parameter: str, env: Mapping[str, str]) -> None:
    """Refuse a Gazebo Transport implementation we do not have: the ``parameter``'s value, or
    when empty, ``GZ_TRANSPORT_IMPLEMENTATION`` of ``env``, as the transport chooses.

    Raises:
        ConfigError: naming where the value came from and the values there are.
    """
    if parameter:
        chosen, where = parameter, "parameter gz_transport_implementation"
        fix = f"or leave it out to follow {TRANSPORT_IMPLEMENTATION_ENV}"
    else:
        chosen, where = env.get(TRANSPORT_IMPLEMENTATION_ENV, ""), TRANSPORT_IMPLEMENTATION_ENV
        fix = "or unset it (zeromq)"
    # "memory" is the tests' in-process backend: it reaches no Gazebo.
    offered = sorted(name for name in BACKENDS if name != "memory")
    if chosen and chosen.lower() not in offered:
        msg = (
            f"{where} is {chosen!r}, not a Gazebo Transport implementation; use one of "
            f"{', '.join(offered)}, {fix}"
        )
        raise ConfigError(msg)


def checked_max_rate(shared: SharedParameters) -> tuple[float, str]:
    """(the ``max_rate`` parameter as a rate, "") or (0, what is wrong with it, for the log)."""
    try:
        return as_rate("max_rate", shared.max_rate), ""
    except ConfigError as err:
        return 0.0, f"parameter {err.message}; no limit is applied"


def checked_max_queued_bytes(shared: SharedParameters) -> tuple[int, str]:
    """(the ``max_queued_bytes`` parameter, "") or (the default, what is wrong with it, for
    the log): a queue must be able to hold something."""
    if shared.max_queued_bytes >= 1:
        return shared.max_queued_bytes, ""
    return MAX_QUEUED_BYTES, (
        f"parameter max_queued_bytes is {shared.max_queued_bytes}; it must be at least 1 "
        f"(bytes a channel's queue holds); using {MAX_QUEUED_BYTES}"
    )


def declare_image_bridge_parameters(
    node: Any, env: Mapping[str, str] | None = None
) -> ImageBridgeParameters:
    """Declare ``image_bridge``'s parameters on ``node`` and return their values."""
    shared = declare_shared_parameters(node, env)
    return _declare_fields(node, ImageBridgeParameters(shared), ("shared",))
