"""Two robots of one simulation, one bridge each in its namespace, and ``/clock`` bridged once.

    ros2 launch ros_gz_bridge_py multi_robot_bridge.launch.py

Each robot's bridge runs in its namespace with ``expand_gz_topic_names``, so the relative
names of ``launch_examples/config/robot_bridge.yaml`` become ``/robot1/cmd_vel`` ... on both the
ROS and the Gazebo side (spawn the robots with their Gazebo topics under ``/robot1``,
``/robot2``). ``/clock`` is global: a single bridge carries it. Bridging it once per robot makes
every ROS node see each clock message several times, and time jumps back (ros_gz issue 591:
"Detected jump back in time", TF buffers cleared).
"""

from pathlib import Path

from launch import LaunchDescription
from launch_ros.actions import Node

#: The package root: the repository, or share/ros_gz_bridge_py once colcon-installed.
PACKAGE_ROOT = Path(__file__).resolve().parent.parent
ROBOT_CONFIG = "launch_examples/config/robot_bridge.yaml"
ROBOTS = ("robot1", "robot2")


def robot_bridge(namespace: str) -> Node:
    return Node(
        package="ros_gz_bridge_py",
        executable="parameter_bridge",
        name="ros_gz_bridge",
        namespace=namespace,
        output="screen",
        parameters=[
            {
                "config_file": str(PACKAGE_ROOT / ROBOT_CONFIG),
                "expand_gz_topic_names": True,
                "use_sim_time": True,
            }
        ],
    )


def generate_launch_description() -> LaunchDescription:
    clock_bridge = Node(
        package="ros_gz_bridge_py",
        executable="parameter_bridge",
        name="clock_bridge",
        output="screen",
        arguments=["/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock"],
    )
    return LaunchDescription([clock_bridge, *(robot_bridge(robot) for robot in ROBOTS)])
