"""The ROS arguments of an executable, checked before rclpy reads them: rclpy raised what rcl
cannot read from ``rclpy.init`` and ``remove_ros_args``, which ended the process with a
traceback; here it is one line naming the argument and how to write it.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable, Sequence
from typing import Any

import yaml
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.utilities import remove_ros_args

from ros_gz_bridge_py.config.names import ROS_NAME_RULE
from ros_gz_bridge_py.errors import RCL_SOURCE_LOCATION

#: rcl's words for a kind of ROS argument, and how to write one.
_ROS_ARGUMENT_FIXES = (
    ("parameter override", "write -p NAME:=VALUE with a value, e.g. -p config_file:=bridge.yaml"),
    ("params", "give --params-file the path of a readable parameters YAML file"),
    (
        "remap",
        f"write -r FROM:=TO, e.g. -r __ns:=/robot1; {ROS_NAME_RULE}, and a node name starts "
        "with a letter",
    ),
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
        fix = _bridge_list_fix(reason) or next(
            (fix for words, fix in _ROS_ARGUMENT_FIXES if words in reason), None
        )
        return f"{program}: bad ROS argument: {reason}; {fix or _ROS_ARGUMENTS_GUIDE}"
    return ""


def _bridge_list_fix(reason: str) -> str:
    """The fix when rcl could not read a ``--params-file`` that is a list of bridges (the
    bridge's own YAML, which ``config_file`` takes); '' otherwise."""
    found = re.search(r"--params-file (.+?)'", reason)
    if found is None:
        return ""
    try:
        with open(found.group(1), encoding="utf-8") as stream:
            document = yaml.safe_load(stream)
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return ""
    if not isinstance(document, list):
        return ""
    return (
        "that file is a list of bridges, not a parameters file: give it as "
        f"-p config_file:={found.group(1)}"
    )


def _rcl_reason(message: str) -> str:
    """rcl's ``message`` without its prefix and source locations, and for a rule without the
    state of rcl's lexer, which names nothing the user wrote."""
    reason = RCL_SOURCE_LOCATION.sub("", message).removeprefix("Failed to parse ROS arguments: ")
    head = reason.partition(". Error: ")[0]
    return (head if " rule: " in head else reason).rstrip(".")


def unknown_parameters(
    program: str,
    argv: Sequence[str],
    node: Any,
    dotted_problem: Callable[[str], str] | None = None,
) -> list[str]:
    """A warning for each ``-p NAME:=VALUE`` of ``argv``'s ROS arguments, and each parameter of
    a ``--params-file`` section for this node by name, that names no parameter ``node`` has
    declared, with the closest name it has: rcl keeps such a value without a word, so a
    misspelt ``lazzy:=true`` left ``lazy`` at its default unnoticed.

    Dotted names (``qos_overrides.*``, ``bridges.*``) are declared as the topics and bridges
    they name are made: ``dotted_problem`` judges them (a warning, or ''), else they are left
    out. So are names for another node (``other:NAME``) and a parameters file's wildcard
    sections (``/**``), which launch files share between nodes.
    """
    names = _parameter_names(argv, node.get_name(), node.get_fully_qualified_name())
    judged = [dotted_problem(name) for name in names if "." in name] if dotted_problem else []
    warnings = [warning for warning in judged if warning]
    unknown = [name for name in names if "." not in name and not node.has_parameter(name)]
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


def _parameter_names(argv: Sequence[str], node_name: str, full_name: str = "") -> list[str]:
    """The names the ``-p``/``--param`` rules of ``argv``'s ROS arguments set for
    ``node_name`` (or for every node), and the ``--params-file`` sections for ``full_name``
    (or ``node_name`` at the root) set, in order, once each."""
    names: list[str] = []
    in_ros = False
    option = ""
    for arg in argv:
        if arg == "--ros-args":
            in_ros, option = True, ""
        elif in_ros and arg == "--":
            in_ros = False
        elif in_ros and option == "--params-file":
            option = ""
            names += _file_parameter_names(arg, node_name, full_name)
        elif in_ros and option:
            option = ""
            target, colon, name = arg.partition(":=")[0].rpartition(":")
            if not colon or target in (node_name, "*"):
                names.append(name)
        elif in_ros and arg in ("-p", "--param", "--params-file"):
            option = "--params-file" if arg == "--params-file" else "-p"
    return [name for name in dict.fromkeys(names) if name]


def _file_parameter_names(path: str, node_name: str, full_name: str) -> list[str]:
    """The parameter names (a nested block's joined with '.') of the sections of the
    parameters file ``path`` for the node ``full_name`` (``/ns/name``; a plain ``name``
    section is the root namespace's); none when the file cannot be read (rcl has said so)."""
    try:
        with open(path, encoding="utf-8") as stream:
            document = yaml.safe_load(stream)
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return []
    own = (full_name or node_name).lstrip("/")
    return [
        name
        for section, parameters in _sections(document, "")
        if section.lstrip("/") == own
        for name in parameters
    ]


def _sections(document: object, prefix: str) -> list[tuple[str, list[str]]]:
    """(node path, its ``ros__parameters`` names) for every section of a parameters file, the
    nested namespace keys joined with '/'."""
    if not isinstance(document, dict):
        return []
    found: list[tuple[str, list[str]]] = []
    for key, value in document.items():
        if key == "ros__parameters" and isinstance(value, dict):
            found.append((prefix, _dotted_names(value)))
        elif isinstance(value, dict):
            found += _sections(value, f"{prefix}/{str(key).strip('/')}" if prefix else str(key))
    return found


def _dotted_names(parameters: dict[Any, Any]) -> list[str]:
    """The names rcl gives the values of a ``ros__parameters`` block: a nested block's
    (``qos_overrides:``) joined with '.'."""
    names: list[str] = []
    for key, value in parameters.items():
        if isinstance(value, dict):
            names += [f"{key}.{name}" for name in _dotted_names(value)]
        else:
            names.append(str(key))
    return names
