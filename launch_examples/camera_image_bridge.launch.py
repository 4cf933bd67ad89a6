"""A Gazebo camera to ROS through ``image_bridge``, with the sensor-data QoS cameras use.

    ros2 launch ros_gz_bridge_py camera_image_bridge.launch.py [image_topic:=/camera]

The topic name is used on both sides. ``qos`` is a node parameter (``-p qos:=sensor_data`` on a
command line; ros_gz_image's README shows it without ``-p``, which does nothing).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "image_topic",
                default_value="/camera",
                description="Gazebo camera topic, bridged to the same ROS topic",
            ),
            Node(
                package="ros_gz_bridge_py",
                executable="image_bridge",
                name="ros_gz_image",
                output="screen",
                arguments=[LaunchConfiguration("image_topic")],
                parameters=[{"qos": "sensor_data", "use_sim_time": True}],
            ),
        ]
    )
