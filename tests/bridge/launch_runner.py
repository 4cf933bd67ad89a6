"""Run a launch description as ``ros2 launch`` does, for the launch tests (ROS launch needed).

Usage::

    python launch_runner.py FILE [NAME:=VALUE ...]   a .launch.py, XML or YAML launch file
    python launch_runner.py --action JSON            one RosGzBridge(**JSON) action

Like ``ros2 launch``: the file is included with the arguments as its launch arguments, a SIGINT
is passed on to the processes where there is no terminal (``--noninteractive``, its default
then), and the process ends with ``LaunchService.run()``'s status.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import Any

from launch import LaunchDescription, LaunchService
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import AnyLaunchDescriptionSource

from ros_gz_bridge_py.actions import RosGzBridge


def description(args: Sequence[str]) -> Any:
    if args[0] == "--action":
        return LaunchDescription([RosGzBridge(**json.loads(args[1]))])
    arguments = [tuple(arg.split(":=", 1)) for arg in args[1:]]
    source = AnyLaunchDescriptionSource(args[0])
    return LaunchDescription([IncludeLaunchDescription(source, launch_arguments=arguments)])


def main(args: Sequence[str]) -> int:
    # As ros2 launch: without a terminal, a SIGINT is for launch alone, which passes it on.
    service = LaunchService(argv=list(args), noninteractive=not sys.stdin.isatty())
    service.include_launch_description(description(args))
    status: int = service.run()
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
