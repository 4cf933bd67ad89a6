"""``parameter_bridge`` positional arguments (``name@ros_type@gz_type`` ...) parsed into specs.

The grammar and the delimiter precedence are the C++ bridge's (docs/behaviour.md §2.1, §2.2): the
first ``@`` ends the name; in the rest an ``@`` (not first) wins over ``[``, which wins over
``]``, wherever they are; a ROS type containing ``/srv/`` makes a service bridge. Every
argument C++ answers with the usage text, and the two it gets wrong silently, raise
:class:`UsageError` naming the argument and the fix.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from ros_gz_bridge_py.config import templates
from ros_gz_bridge_py.config.model import (
    BridgeSpec,
    Direction,
    ParseResult,
    ServiceBridgeSpec,
    TopicBridgeSpec,
    UsageError,
    ros_type_hint,
)
from ros_gz_bridge_py.errors import ConfigError

USAGE = (
    """\
Bridge a collection of ROS 2 and Gazebo Transport topics and services.

  parameter_bridge [<topic@ROS2_type@Gz_type> ..]
                   [<service@ROS2_srv_type[@Gz_req_type@Gz_rep_type]> ..]

Topics: the first @ separates the topic name (used on both sides) from the types.
After it comes the ROS message type, then one direction symbol, then the Gazebo type:
    @  bidirectional bridge
    [  bridge from Gazebo to ROS
    ]  bridge from ROS to Gazebo

Services: the first @ separates the service name from the ROS service type, optionally
followed by the Gazebo request and reply types, each after an @. Only Gazebo services can
be offered as ROS services: the ROS service forwards each request to the Gazebo service and
sends its reply back to the ROS client.

A bidirectional bridge:
    parameter_bridge /chatter@std_msgs/msg/String@gz.msgs.StringMsg
A bridge from Gazebo to ROS:
    parameter_bridge /chatter@std_msgs/msg/String[gz.msgs.StringMsg
A bridge from ROS to Gazebo:
    parameter_bridge /chatter@std_msgs/msg/String]gz.msgs.StringMsg
A service bridge:
    parameter_bridge /world/default/control@ros_gz_interfaces/srv/ControlWorld
or, with the Gazebo types spelled out:
    parameter_bridge /world/default/control@ros_gz_interfaces/srv/ControlWorld"""
    "@gz.msgs.WorldControl@gz.msgs.Boolean"
    """

Bridges can also come from a YAML file: --ros-args -p config_file:=<path>
(quote arguments that contain [ or ] in zsh).

Ours: NAME=VALUE[,VALUE...] gives the values of ${NAME} in arguments and the YAML;
--ros-args -p auto_bridge:=true bridges every Gazebo topic discovery shows;
--discover [SECONDS] prints the YAML of them; --check [SECONDS] checks each entry.
"""
)

#: Direction symbols, in the order the C++ parser tries them.
_DELIMITERS: tuple[tuple[str, Direction], ...] = (
    ("@", Direction.BIDIRECTIONAL),
    ("[", Direction.GZ_TO_ROS),
    ("]", Direction.ROS_TO_GZ),
)

_FORM = "write <name>@<ROS type>@<Gazebo type> ([ for Gazebo->ROS, ] for ROS->Gazebo)"


def _find_delimiter(rest: str) -> tuple[int, Direction | None]:
    """Position and meaning of the direction symbol; (-1, None) when there is none.

    A symbol at position 0 does not count (there would be no ROS type before it); C++
    then tries the next symbol, except for ``]``, which it rejects.
    """
    for symbol, direction in _DELIMITERS:
        position = rest.find(symbol)
        if position > 0:
            return position, direction
        if position == 0 and symbol == "]":
            return 0, direction
    return -1, None


def _parse_service(
    name: str, ros_type: str, direction: Direction | None, after: str, *, source: str, fail: str
) -> ServiceBridgeSpec:
    if direction is None:
        return ServiceBridgeSpec(name, ros_type, source=source)
    if direction is not Direction.BIDIRECTIONAL:
        msg = (
            "a service bridge has no direction symbol; write "
            f"{name}@{ros_type} or {name}@{ros_type}@<Gazebo request type>@<Gazebo reply type>"
        )
        raise UsageError(
            msg,
            fail,
        )
    req_type, at, rep_type = after.partition("@")
    if not at or not req_type:
        msg = (
            "a service bridge takes both Gazebo types or neither; write "
            f"{name}@{ros_type}@<Gazebo request type>@<Gazebo reply type>"
        )
        raise UsageError(
            msg,
            fail,
        )
    return ServiceBridgeSpec(name, ros_type, req_type, rep_type or None, source=source)


def _parse_arg(arg: str, position: int) -> tuple[BridgeSpec, list[str]]:
    """One argument (``position`` is 1-based) as a spec plus warnings; raises UsageError."""
    source = f"argument {position}"
    fail = f"{source} '{arg}'"
    name, at, rest = arg.partition("@")
    if not at:
        msg = f"no '@' after the topic or service name; {_FORM}"
        raise UsageError(msg, fail)
    if not name:
        msg = f"no topic or service name before the first '@'; {_FORM}"
        raise UsageError(msg, fail)
    position_in_rest, direction = _find_delimiter(rest)
    if position_in_rest == 0:
        msg = f"no ROS type before ']'; {_FORM}"
        raise UsageError(msg, fail)
    if direction is None:
        ros_type, after = rest, ""
    else:
        ros_type, after = rest[:position_in_rest], rest[position_in_rest + 1 :]
    if not ros_type or ros_type.startswith(("@", "[")):
        msg = f"no ROS type after the first '@'; {_FORM}"
        raise UsageError(msg, fail)
    warnings = [f"{source}: {hint}"] if (hint := ros_type_hint(ros_type)) else []
    if "/srv/" in ros_type:
        return _parse_service(name, ros_type, direction, after, source=source, fail=fail), warnings
    if direction is None:
        stray = next((c for c in ros_type if not (c.isalnum() or c in "_/")), None)
        if stray is not None:  # '/clock@rosgraph_msgs/msg/Clock<gz.msgs.Clock'
            msg = (
                f"'{stray}' is no direction symbol; between the ROS and the Gazebo type write "
                "@ (both ways), [ (Gazebo->ROS) or ] (ROS->Gazebo)"
            )
            raise UsageError(msg, fail)
        msg = f"no Gazebo type; write {arg}@gz.msgs.X ([ for Gazebo->ROS, ] for ROS->Gazebo)"
        raise UsageError(msg, fail)
    if not after:
        msg = f"no Gazebo type after the direction symbol; {_FORM}"
        raise UsageError(msg, fail)
    if "@" in after:
        msg = f"more than one '@' after the ROS type; {_FORM}"
        raise UsageError(msg, fail)
    for symbol in "[]":
        if symbol in ros_type:
            warnings.append(
                f"{source}: ROS type '{ros_type}' contains '{symbol}' because an '@' later in the "
                "argument takes precedence; use exactly one direction symbol"
            )
    return TopicBridgeSpec(name, name, ros_type, after, direction, source=source), warnings


def cli_placeholders(args: Sequence[str]) -> dict[str, tuple[str, ...]]:
    """The placeholder values given as ``NAME=VALUE`` arguments (``templates.py``)."""
    assignments = [arg for arg in args if templates.is_assignment(arg)]
    return templates.parse_assignments(assignments, "argument")


def parse_cli_args(
    args: Sequence[str], placeholders: templates.Placeholders | None = None
) -> ParseResult:
    """Parse ``parameter_bridge`` positional arguments (ROS arguments already removed).

    ``NAME=VALUE`` arguments are placeholder values (:func:`cli_placeholders`) and skipped;
    an argument with ``${name}`` placeholders makes one bridge per value. Raises
    :class:`UsageError` for the first argument that cannot be parsed, as C++ stops there. An
    empty ``args`` is a valid, empty result (bridges may come from a YAML file).
    """
    specs: list[BridgeSpec] = []
    warnings: list[str] = []
    for position, arg in enumerate(args, start=1):
        if templates.is_assignment(arg):
            continue
        where = f"argument {position} '{arg}'"
        try:
            names = templates.names_in([arg])
            choices = templates.combinations(names, placeholders or {}, where)
        except ConfigError as err:
            raise UsageError(err.message.removeprefix("Could not parse entry: "), where) from err
        for chosen in choices:
            spec, arg_warnings = _parse_arg(templates.substitute(arg, chosen, where), position)
            if chosen:
                spec = dataclasses.replace(spec, source=spec.source + templates.describe(chosen))
            specs.append(spec)
            warnings.extend(arg_warnings)
    return ParseResult(tuple(specs), (), tuple(warnings))
