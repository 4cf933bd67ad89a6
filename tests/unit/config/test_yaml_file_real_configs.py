"""The real bridge files of ``config/`` load unchanged, as the users who wrote them expect, and
are the shared files they were taken from."""

from __future__ import annotations

from pathlib import Path

import pytest

from ros_gz_bridge_py.config import Direction, ParseResult, TopicBridgeSpec, read_yaml_file

EXAMPLES = Path(__file__).parents[3] / "config"


_REAL_ENTRIES = [
    ("clock", "clock", "rosgraph_msgs/msg/Clock", "gz.msgs.Clock", Direction.GZ_TO_ROS),
    (
        "joint_states",
        "joint_states",
        "sensor_msgs/msg/JointState",
        "gz.msgs.Model",
        Direction.GZ_TO_ROS,
    ),
    ("odom", "odom", "nav_msgs/msg/Odometry", "gz.msgs.Odometry", Direction.GZ_TO_ROS),
    ("tf", "tf", "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V", Direction.GZ_TO_ROS),
    ("cmd_vel", "cmd_vel", "geometry_msgs/msg/Twist", "gz.msgs.Twist", Direction.ROS_TO_GZ),
    ("imu", "imu", "sensor_msgs/msg/Imu", "gz.msgs.IMU", Direction.GZ_TO_ROS),
    ("scan", "scan", "sensor_msgs/msg/LaserScan", "gz.msgs.LaserScan", Direction.GZ_TO_ROS),
    (
        "camera/camera_info",
        "camera/camera_info",
        "sensor_msgs/msg/CameraInfo",
        "gz.msgs.CameraInfo",
        Direction.GZ_TO_ROS,
    ),
]


def _rows(result: ParseResult) -> list[tuple[str, str, str, str, Direction]]:
    """The topic entries of ``result`` (it has no other), each as its names, types, direction."""
    topics = [spec for spec in result.specs if isinstance(spec, TopicBridgeSpec)]
    assert len(topics) == len(result.specs)
    return [(s.ros_topic, s.gz_topic, s.ros_type, s.gz_type, s.direction) for s in topics]


def _real_summary(path: Path) -> list[tuple[str, str, str, str, Direction]]:
    result = read_yaml_file(path)
    assert (result.errors, result.warnings) == ((), ())
    for spec in result.specs:
        assert isinstance(spec, TopicBridgeSpec)
        assert (spec.lazy, spec.publisher_queue, spec.subscriber_queue) == (None, None, None)
        assert (spec.qos_profile, spec.frame_id) == (None, None)
    return _rows(result)


def test_turtlebot3_waffle_config_loads_unchanged() -> None:
    path = EXAMPLES / "turtlebot3_waffle_bridge.yaml"
    assert _real_summary(path) == _REAL_ENTRIES
    lines = [spec.source for spec in read_yaml_file(path).specs]
    assert lines[0] == f"{path} entry 1 (line 4)"
    assert lines[-1] == f"{path} entry 8 (line 46)"


def test_fleet_example_is_one_robot_file_per_robot_plus_the_clock() -> None:
    """config/fleet_bridge.yaml (ours, one process) and config/fleet_robot.yaml (the C++
    bridge's form, once per robot namespace) bridge the same topics."""
    robots = ("robot_1", "robot_2")
    fleet = read_yaml_file(EXAMPLES / "fleet_bridge.yaml", {"robot": robots})
    assert (fleet.errors, fleet.warnings) == ((), ())
    one_robot = _real_summary(EXAMPLES / "fleet_robot.yaml")
    per_robot = [
        (f"/{robot}/{ros}", f"/{robot}/{gz}", *rest)
        for robot in robots
        for ros, gz, *rest in one_robot
    ]
    clock = ("/clock", "/clock", "rosgraph_msgs/msg/Clock", "gz.msgs.Clock", Direction.GZ_TO_ROS)
    assert sorted(_rows(fleet)) == sorted([clock, *per_robot])


def test_diff_car_config_loads_unchanged() -> None:
    path = EXAMPLES / "diff_car_bridge.yaml"
    assert _real_summary(path) == [
        *_REAL_ENTRIES,
        (
            "/camera/image",
            "/camera/image",
            "sensor_msgs/msg/Image",
            "gz.msgs.Image",
            Direction.GZ_TO_ROS,
        ),
        (
            "/camera/depth_image",
            "/camera/depth_image",
            "sensor_msgs/msg/Image",
            "gz.msgs.Image",
            Direction.GZ_TO_ROS,
        ),
        (
            "/camera/points",
            "/camera/points",
            "sensor_msgs/msg/PointCloud2",
            "gz.msgs.PointCloudPacked",
            Direction.GZ_TO_ROS,
        ),
    ]


def test_examples_are_the_shared_files_unchanged() -> None:
    shared = Path("/work/shared/data/configs")
    if not shared.is_dir():
        pytest.skip("the shared data directory exists only on the development machine")
    for name in ("turtlebot3_waffle_bridge.yaml", "diff_car_bridge.yaml"):
        assert (EXAMPLES / name).read_bytes() == (shared / name).read_bytes()
