"""What the configuration sources tell the transport before any channel exists."""

from __future__ import annotations

from pathlib import Path

from ros_gz_bridge_py.app.sources import gz_subscriptions
from ros_gz_bridge_py.config.cli import parse_cli_args
from ros_gz_bridge_py.config.yaml_file import read_yaml_file
from ros_gz_bridge_py.transport.settings import planned_rcvhwm

FLEET_YAML = Path(__file__).resolve().parents[3] / "config" / "fleet_bridge.yaml"


def test_the_gazebo_topics_subscribed_are_those_carried_to_ros() -> None:
    """Both ways and Gazebo -> ROS subscribe a Gazebo topic; ROS -> Gazebo does not."""
    cli = parse_cli_args(
        [
            "/both@std_msgs/msg/String@gz.msgs.StringMsg",
            "/to_ros@std_msgs/msg/String[gz.msgs.StringMsg",
            "/to_gz@std_msgs/msg/String]gz.msgs.StringMsg",
        ]
    )
    assert gz_subscriptions([cli]) == 2
    assert gz_subscriptions([]) == 0


def test_a_fleet_of_fifty_robots_plans_the_smallest_receive_queues() -> None:
    """config/fleet_bridge.yaml for 50 robots: /clock and odom, imu, joint_states per robot
    (cmd_vel goes the other way): 151 topics, each with a receive queue of 50 messages."""
    robots = tuple(f"robot_{index}" for index in range(1, 51))
    fleet = read_yaml_file(FLEET_YAML, {"robot": robots})
    assert not fleet.errors
    assert gz_subscriptions([fleet]) == 151
    assert planned_rcvhwm(gz_subscriptions([fleet])) == 50
