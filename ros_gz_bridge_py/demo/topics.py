"""The demo's topics: names as ``config/turtlebot3_waffle_bridge.yaml`` bridges them, plus the
camera image, which the image bridge carries.

World and client both import these, so a rename happens in one place.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

_CONFIG_NAME = "turtlebot3_waffle_bridge.yaml"
_IN_SOURCE_TREE = Path(__file__).resolve().parents[2] / "config" / _CONFIG_NAME
#: Where an installed wheel puts it (setup.cfg's data_files).
INSTALLED_CONFIG_FILE = Path(sys.prefix) / "share" / "ros_gz_bridge_py" / "config" / _CONFIG_NAME
CONFIG_FILE = _IN_SOURCE_TREE if _IN_SOURCE_TREE.exists() else INSTALLED_CONFIG_FILE

CLOCK = "clock"
JOINT_STATES = "joint_states"
ODOM = "odom"
TF = "tf"
CMD_VEL = "cmd_vel"
IMU = "imu"
SCAN = "scan"
CAMERA_INFO = "camera/camera_info"
CAMERA_IMAGE = "camera/image_raw"

ODOM_FRAME = "odom"
BASE_FRAME = "base_footprint"
IMU_FRAME = "imu_link"
SCAN_FRAME = "base_scan"
CAMERA_FRAME = "camera_rgb_optical_frame"
LEFT_WHEEL_JOINT = "wheel_left_joint"
RIGHT_WHEEL_JOINT = "wheel_right_joint"
MODEL_NAME = "waffle"


@dataclass(frozen=True)
class BridgedTopic:
    """One Gazebo -> ROS topic the client watches."""

    name: str
    ros_type: str
    gz_type: str


#: Every Gazebo -> ROS topic of the demo, in table order.
GZ_TO_ROS: tuple[BridgedTopic, ...] = (
    BridgedTopic(CLOCK, "rosgraph_msgs/msg/Clock", "gz.msgs.Clock"),
    BridgedTopic(JOINT_STATES, "sensor_msgs/msg/JointState", "gz.msgs.Model"),
    BridgedTopic(ODOM, "nav_msgs/msg/Odometry", "gz.msgs.Odometry"),
    BridgedTopic(TF, "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V"),
    BridgedTopic(IMU, "sensor_msgs/msg/Imu", "gz.msgs.IMU"),
    BridgedTopic(SCAN, "sensor_msgs/msg/LaserScan", "gz.msgs.LaserScan"),
    BridgedTopic(CAMERA_INFO, "sensor_msgs/msg/CameraInfo", "gz.msgs.CameraInfo"),
    BridgedTopic(CAMERA_IMAGE, "sensor_msgs/msg/Image", "gz.msgs.Image"),
)
