"""TurtleBot3 Waffle in Gazebo: every topic of the ros_gz migration guide's bridge file.

    ros2 launch ros_gz_bridge_py turtlebot3_bridge.launch.py [config_file:=...] [status_period:=1.0]

``status_period`` > 0 publishes each bridged topic's counters on ``/diagnostics``.
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

#: The package root: the repository, or share/ros_gz_bridge_py once colcon-installed.
PACKAGE_ROOT = Path(__file__).resolve().parent.parent
CONFIG_FILE = "config/turtlebot3_waffle_bridge.yaml"


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "config_file",
                default_value=str(PACKAGE_ROOT / CONFIG_FILE),
                description="YAML file of the bridges",
            ),
            DeclareLaunchArgument(
                "status_period",
                default_value="0.0",
                description="seconds between /diagnostics status messages (0 = off)",
            ),
            Node(
                package="ros_gz_bridge_py",
                executable="parameter_bridge",
                name="ros_gz_bridge",
                output="screen",
                parameters=[
                    {
                        "config_file": LaunchConfiguration("config_file"),
                        "status_period": LaunchConfiguration("status_period"),
                        "use_sim_time": True,
                    }
                ],
            ),
        ]
    )
