"""ros_gz_bridge's ros_gz_bridge.launch.py (Jazzy) for this bridge: the same arguments and defaults.

    ros2 launch ros_gz_bridge_py ros_gz_bridge.launch.py bridge_name:=<name> config_file:=<yaml>

Starts ``bridge_node`` through the ``RosGzBridge`` action (ros_gz_bridge_py.actions). This
bridge is Python: with use_composition:=True it says so in one line and runs as its own process.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration

from ros_gz_bridge_py.actions import RosGzBridge
from ros_gz_bridge_py.app.bridge_launch import LAUNCH_ARGUMENTS


def generate_launch_description() -> LaunchDescription:
    declared = [
        DeclareLaunchArgument(argument.name, description=argument.description)
        if argument.default is None
        else DeclareLaunchArgument(
            argument.name, default_value=argument.default, description=argument.description
        )
        for argument in LAUNCH_ARGUMENTS
    ]
    bridge = RosGzBridge(
        **{argument.name: LaunchConfiguration(argument.name) for argument in LAUNCH_ARGUMENTS}
    )
    return LaunchDescription([*declared, bridge])
