"""``bridge_node``: ros_gz_bridge's ``bridge_node``, the bridge configured by node parameters only.

In ros_gz (Jazzy), ``bridge_node`` is the ``ros_gz_bridge::RosGzBridge`` component run as a
process of its own: what ``ros_gz_bridge.launch.py`` and the ``RosGzBridge`` launch action start.
It takes no topic arguments; it reads its parameters (``config_file``, ``expand_gz_topic_names``,
``bridge_names`` and ``bridges.<name>.*``, ``subscription_heartbeat``, ``lazy``,
``override_timestamps_with_wall_time``, ``override_frame_id``, ``qos_overrides.*``), and its node
is named ``ros_gz_bridge`` unless renamed (a launch file's ``name=bridge_name`` is
``--ros-args -r __node:=<bridge_name>``; docs/behaviour.md §1.3).

Here it is ``parameter_bridge`` given only the ROS arguments: the same parameters (ours too), the
same node name, start-up and shutdown. Arguments outside ``--ros-args`` are named in one line on
stderr and not bridged, where the C++ executable ignores them without a word.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from ros_gz_bridge_py.app import parameter_bridge
from ros_gz_bridge_py.app.ros_arguments import ros_arguments_problem
from ros_gz_bridge_py.ros.stop_signal import StopSignal

PROGRAM = "bridge_node"
#: rcl's markers: ROS arguments run from ``--ros-args`` to ``--`` (or the end), repeatably.
ROS_ARGS = "--ros-args"
END_OF_ROS_ARGS = "--"
USAGE = f"""\
Bridge ROS 2 and Gazebo Transport topics and services listed in node parameters
(ros_gz_bridge's bridge_node: what ros_gz_bridge.launch.py and the RosGzBridge launch action run).

  {PROGRAM} --ros-args -p config_file:=<bridge.yaml> [-r __node:=<name>] [-r __ns:=<namespace>]

Its parameters are parameter_bridge's (docs/configuration.md, Node parameters); its node is named
ros_gz_bridge unless renamed. Topics given as arguments are not read: list them in config_file
(or in bridge_names / bridges.<name>.* parameters), or run parameter_bridge instead."""


def split_arguments(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """(the ROS arguments of ``argv[1:]`` with their markers, the other arguments)."""
    ros: list[str] = []
    others: list[str] = []
    inside = False
    for arg in argv[1:]:
        if arg == ROS_ARGS:
            inside = True
            ros.append(arg)
        elif inside:
            inside = arg != END_OF_ROS_ARGS
            ros.append(arg)
        else:
            others.append(arg)
    return ros, others


def main(argv: Sequence[str] | None = None, stop: StopSignal | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    ros, others = split_arguments(argv)
    if any(arg in ("-h", "--help") for arg in others):
        print(USAGE)
        return 0
    problem = ros_arguments_problem(PROGRAM, [argv[0], *ros])
    if problem:
        print(problem, file=sys.stderr)
        return parameter_bridge.USAGE_EXIT
    if others:
        print(
            f"{PROGRAM}: not bridged: {' '.join(others)} ({PROGRAM} reads only parameters: list "
            "the topics in config_file, or run parameter_bridge with them)",
            file=sys.stderr,
        )
    # parameter_bridge prints its usage when given nothing at all; an empty ROS section is
    # "no arguments" for rcl, and bridge_node without parameters runs (it bridges nothing).
    return parameter_bridge.main([argv[0], *(ros or [ROS_ARGS])], stop=stop)


if __name__ == "__main__":
    sys.exit(main())
