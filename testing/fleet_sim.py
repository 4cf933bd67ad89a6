"""The simulated fleet of issue 28: what the C++ peer's ``pub-fleet`` mode publishes.

One simulator process publishes ``/clock`` at 1 kHz and, per robot ``robot_<i>``, ``odom``
(Odometry, 50 Hz), ``imu`` (IMU, 200 Hz) and ``joint_states`` (Model with two joints, 100 Hz),
and subscribes to each robot's ``cmd_vel`` (Twist), as ``config/fleet_bridge.yaml`` bridges
them. Every robot's messages carry its index, so a message on the wrong robot's topic shows:
``expected_ros`` says what the ROS side must receive. Used by ``tests/bridge/test_fleet_e2e.py``
and ``benchmarks/fleet.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / "config" / "fleet_bridge.yaml"
CLOCK_TOPIC = "/clock"
CLOCK_HZ = 1000.0
#: ``/clock``'s message, and what the bridge makes of it.
CLOCK_TEXT = "sim { sec: 1234 nsec: 5678 }"
CLOCK_ROS = {"clock": {"sec": 1234, "nanosec": 5678}}
#: ROS -> Gazebo commands per robot and second (issue 28).
CMD_VEL_HZ = 10.0


@dataclass(frozen=True)
class RobotKind:
    """One Gazebo -> ROS topic every robot has."""

    name: str
    ign_type: str
    ros_type: str
    hz: float

    def topic(self, robot: str) -> str:
        return f"/{robot}/{self.name}"


ODOM = RobotKind("odom", "ignition.msgs.Odometry", "nav_msgs/msg/Odometry", 50.0)
IMU = RobotKind("imu", "ignition.msgs.IMU", "sensor_msgs/msg/Imu", 200.0)
JOINT_STATES = RobotKind("joint_states", "ignition.msgs.Model", "sensor_msgs/msg/JointState", 100.0)
KINDS = (ODOM, IMU, JOINT_STATES)
CMD_VEL_TYPE = "geometry_msgs/msg/Twist"


def robots(count: int) -> list[str]:
    """``robot_1`` ... ``robot_<count>``."""
    return [f"robot_{i}" for i in range(1, count + 1)]


def robot_index(robot: str) -> int:
    return int(robot.rsplit("_", 1)[1])


def gz_text(kind: RobotKind, robot: str) -> str:
    """The message ``robot`` publishes on ``kind``'s topic (protobuf text, one line)."""
    i = robot_index(robot)
    if kind is ODOM:
        return f"pose {{ position {{ x: {i} y: -{i} }} }} twist {{ linear {{ x: 0.5 }} }}"
    if kind is IMU:
        return f"angular_velocity {{ z: {i} }} linear_acceleration {{ z: 9.75 }}"
    return (
        f'joint {{ name: "left_wheel" axis1 {{ position: {i} velocity: 0.25 }} }}'
        f' joint {{ name: "right_wheel" axis1 {{ position: -{i} velocity: -0.25 }} }}'
    )


def expected_ros(kind: RobotKind, robot: str) -> dict[str, Any]:
    """The fields of the ROS message ``robot``'s ``kind`` message must become."""
    i = float(robot_index(robot))
    if kind is ODOM:
        return {
            "pose": {"pose": {"position": {"x": i, "y": -i}}},
            "twist": {"twist": {"linear": {"x": 0.5}}},
        }
    if kind is IMU:
        return {"angular_velocity": {"z": i}, "linear_acceleration": {"z": 9.75}}
    return {
        "name": ["left_wheel", "right_wheel"],
        "position": [i, -i],
        "velocity": [0.25, -0.25],
    }


def cmd_vel_topic(robot: str) -> str:
    return f"/{robot}/cmd_vel"


def cmd_vel_values(robot: str) -> dict[str, Any]:
    """The Twist a ROS node sends ``robot`` (its index in ``linear.x``)."""
    return {"linear": {"x": robot_index(robot) + 0.5}, "angular": {"z": -0.25}}


def write_spec(path: Path, names: list[str]) -> Path:
    """The ``pub-fleet`` spec of a fleet of ``names``."""
    lines = [f"pub ignition.msgs.Clock {CLOCK_HZ:g} {CLOCK_TOPIC} {CLOCK_TEXT}"]
    for robot in names:
        lines += [
            f"pub {kind.ign_type} {kind.hz:g} {kind.topic(robot)} {gz_text(kind, robot)}"
            for kind in KINDS
        ]
        lines.append(f"sub ignition.msgs.Twist {cmd_vel_topic(robot)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def bridge_arguments(names: list[str]) -> list[str]:
    """``parameter_bridge`` arguments bridging the fleet of ``names`` with the example file."""
    return [f"robot={','.join(names)}", "--ros-args", "-p", f"config_file:={CONFIG}"]
