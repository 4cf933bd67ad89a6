"""The ROS arguments of an executable, checked before rclpy reads them: rclpy raised what rcl
cannot read from ``rclpy.init`` and ``remove_ros_args``, which ended the process with a
traceback; here it is one line naming the argument and how to write it.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from typing import Any

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.utilities import remove_ros_args

from ros_gz_bridge_py.errors import RCL_SOURCE_LOCATION

#: rcl's words for a kind of ROS argument, and how to write one.
_ROS_ARGUMENT_FIXES = (
    ("parameter override", "write -p NAME:=VALUE with a value, e.g. -p config_file:=bridge.yaml"),
    ("params", "give --params-file the path of a readable parameters YAML file"),
    ("remap", "write -r FROM:=TO, e.g. -r __ns:=/robot1"),
    ("log level", "write --log-level LEVEL: debug, info, warn, error or fatal"),
)
_ROS_ARGUMENTS_GUIDE = "see 'Passing ROS arguments to nodes' in the ROS 2 documentation"


def ros_arguments_problem(program: str, argv: Sequence[str]) -> str:
    """What rcl cannot read in the ROS arguments of ``argv`` (with the program name), as one
    line naming the argument and the fix; '' when it reads them all.

    Checked before ``rclpy.init``: rclpy raises these from it and from ``remove_ros_args``,
    which ended the process with a traceback.
    """
    try:
        remove_ros_args(list(argv))
    except _rclpy.UnknownROSArgsError as err:
        unknown = str(err).removeprefix("[").removesuffix("]")
        return (
            f"{program}: not ROS arguments, yet after --ros-args: {unknown}; put {program}'s "
            "own arguments before --ros-args, or after a -- that ends the ROS arguments"
        )
    except _rclpy.RCLInvalidROSArgsError as err:
        reason = _rcl_reason(str(err))
        fix = next((fix for words, fix in _ROS_ARGUMENT_FIXES if words in reason), None)
        return f"{program}: bad ROS argument: {reason}; {fix or _ROS_ARGUMENTS_GUIDE}"
    return ""


def _rcl_reason(message: str) -> str:
    """rcl's ``message`` without its prefix and source locations, and for a rule without the
    state of rcl's lexer, which names nothing the user wrote."""
    reason = RCL_SOURCE_LOCATION.sub("", message).removeprefix("Failed to parse ROS arguments: ")
    head = reason.partition(". Error: ")[0]
    return (head if " rule: " in head else reason).rstrip(".")


def unknown_parameters(program: str, argv: Sequence[str], node: Any) -> list[str]:
    """A warning for each ``-p NAME:=VALUE`` of ``argv``'s ROS arguments that names no
    parameter ``node`` has declared, with the closest name it has: rcl keeps such a value
    without a word, so a misspelt ``lazzy:=true`` left ``lazy`` at its default unnoticed.

    Dotted names (``qos_overrides.*``, ``bridges.*``) are left out: they are declared as the
    topics and bridges they name are made. So are names for another node (``other:NAME``).
    """
    warnings = []
    unknown = [
        name
        for name in _parameter_names(argv, node.get_name())
        if "." not in name and not node.has_parameter(name)
    ]
    known = list(node.get_parameters_by_prefix("")) if unknown else []
    for name in unknown:
        close = difflib.get_close_matches(name, known, n=1)
        hint = (
            f"; did you mean {close[0]}"
            if close
            else f" (ros2 param list {node.get_fully_qualified_name()} lists them)"
        )
        warnings.append(f"parameter {name} is none of {program}'s, so it changes nothing{hint}")
    return warnings


def _parameter_names(argv: Sequence[str], node_name: str) -> list[str]:
    """The names the ``-p``/``--param`` rules of ``argv``'s ROS arguments set for
    ``node_name`` (or for every node), in order, once each."""
    names: list[str] = []
    in_ros = taking = False
    for arg in argv:
        if arg == "--ros-args":
            in_ros, taking = True, False
        elif in_ros and arg == "--":
            in_ros = False
        elif in_ros and taking:
            taking = False
            target, colon, name = arg.partition(":=")[0].rpartition(":")
            if (not colon or target in (node_name, "*")) and name and name not in names:
                names.append(name)
        elif in_ros:
            taking = arg in ("-p", "--param")
    return names
