"""The ROS arguments of an executable, checked before rclpy reads them: rclpy raised what rcl
cannot read from ``rclpy.init`` and ``remove_ros_args``, which ended the process with a
traceback; here it is one line naming the argument and how to write it.
"""

from __future__ import annotations

from collections.abc import Sequence

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
