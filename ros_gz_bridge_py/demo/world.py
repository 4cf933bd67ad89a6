"""The demo's Gazebo side: a TurtleBot3-like robot on our own Gazebo Transport node.

It publishes what the Gazebo Harmonic plugins of a TurtleBot3 Waffle publish (clock, joint
states, odometry, tf, IMU, lidar, camera info and image; ``gz.msgs.*`` types) and obeys
``cmd_vel``. Sim time is the wall clock (real-time factor 1): every stamp and the clock itself
are ``time.time()`` at the physics step, so a subscriber's "now - stamp" is the true latency.

Run as ``python -m ros_gz_bridge_py.demo.world``; it prints ``READY`` once advertised and runs
until SIGINT or SIGTERM.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any

from ros_gz_bridge_py.demo import sim, topics
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import GzNode, MessageInfo, Publisher, create_gz_node

#: Physics steps per second; the publish periods below are in steps.
STEP_HZ = 100
CLOCK_PERIOD = 1
IMU_PERIOD = 2
ODOM_PERIOD = 3
CAMERA_PERIOD = 10
SCAN_PERIOD = 20
#: Longest step integrated at once (after a stall the robot does not jump).
MAX_DT = 0.05

SCAN_BEAMS = 360
RANGE_MIN = 0.12
RANGE_MAX = 3.5
IMAGE_WIDTH = 160
IMAGE_HEIGHT = 120
CAMERA_FOV = 1.085
RGB_INT8 = 3
GRAVITY = 9.80665
#: Diagonal of the IMU covariances (orientation, angular velocity, linear acceleration).
IMU_VARIANCES = (1e-3, 2e-4, 1.7e-2)

GzClock = message_class("gz.msgs.Clock")
GzModel = message_class("gz.msgs.Model")
GzOdometry = message_class("gz.msgs.Odometry")
GzPoseV = message_class("gz.msgs.Pose_V")
GzImu = message_class("gz.msgs.IMU")
GzLaserScan = message_class("gz.msgs.LaserScan")
GzCameraInfo = message_class("gz.msgs.CameraInfo")
GzImage = message_class("gz.msgs.Image")
GzTwist = message_class("gz.msgs.Twist")


def fill_time(gz_time: Any, seconds: float) -> None:
    whole = math.floor(seconds)
    gz_time.sec = whole
    gz_time.nsec = min(round((seconds - whole) * 1e9), 999_999_999)


def fill_header(header: Any, stamp: float, frame_id: str, child_frame_id: str = "") -> None:
    """Stamp and frames as Gazebo writes them: ``data`` entries keyed frame_id/child_frame_id."""
    fill_time(header.stamp, stamp)
    header.data.add(key="frame_id", value=[frame_id])
    if child_frame_id:
        header.data.add(key="child_frame_id", value=[child_frame_id])


def fill_pose(pose: Any, state: sim.RobotState) -> None:
    pose.position.x = state.x
    pose.position.y = state.y
    qx, qy, qz, qw = sim.yaw_quaternion(state.yaw)
    pose.orientation.x, pose.orientation.y = qx, qy
    pose.orientation.z, pose.orientation.w = qz, qw


def diagonal(variance: float) -> list[float]:
    return [variance if row == col else 0.0 for row in range(3) for col in range(3)]


def clock_message(stamp: float) -> Any:
    msg = GzClock()
    for field in (msg.sim, msg.real, msg.system):
        fill_time(field, stamp)
    return msg


def joint_states_message(state: sim.RobotState, stamp: float) -> Any:
    msg = GzModel(name=topics.MODEL_NAME)
    fill_header(msg.header, stamp, topics.MODEL_NAME)
    left_speed, right_speed = sim.wheel_speeds(state.linear, state.angular)
    for name, position, speed in (
        (topics.LEFT_WHEEL_JOINT, state.left_wheel, left_speed),
        (topics.RIGHT_WHEEL_JOINT, state.right_wheel, right_speed),
    ):
        joint = msg.joint.add(name=name)
        joint.axis1.position = position
        joint.axis1.velocity = speed
    return msg


def odometry_message(state: sim.RobotState, stamp: float) -> Any:
    msg = GzOdometry()
    fill_header(msg.header, stamp, topics.ODOM_FRAME, topics.BASE_FRAME)
    fill_pose(msg.pose, state)
    msg.twist.linear.x = state.linear
    msg.twist.angular.z = state.angular
    return msg


def tf_message(state: sim.RobotState, stamp: float) -> Any:
    msg = GzPoseV()
    pose = msg.pose.add(name=topics.BASE_FRAME)
    fill_header(pose.header, stamp, topics.ODOM_FRAME, topics.BASE_FRAME)
    fill_pose(pose, state)
    return msg


def imu_message(state: sim.RobotState, stamp: float) -> Any:
    msg = GzImu(entity_name=topics.IMU_FRAME)
    fill_header(msg.header, stamp, topics.IMU_FRAME)
    qx, qy, qz, qw = sim.yaw_quaternion(state.yaw)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = qx, qy, qz, qw
    msg.angular_velocity.z = state.angular
    # On a circle the body feels the centripetal acceleration sideways, and gravity.
    msg.linear_acceleration.y = state.linear * state.angular
    msg.linear_acceleration.z = GRAVITY
    for covariance, variance in zip(
        (
            msg.orientation_covariance,
            msg.angular_velocity_covariance,
            msg.linear_acceleration_covariance,
        ),
        IMU_VARIANCES,
        strict=True,
    ):
        covariance.data.extend(diagonal(variance))
    return msg


def scan_message(state: sim.RobotState, stamp: float, room: sim.Room) -> Any:
    angles = sim.scan_angles(SCAN_BEAMS)
    msg = GzLaserScan(
        frame=topics.SCAN_FRAME,
        angle_min=0.0,
        angle_max=float(angles[-1]),
        angle_step=math.tau / SCAN_BEAMS,
        range_min=RANGE_MIN,
        range_max=RANGE_MAX,
        count=SCAN_BEAMS,
        vertical_count=1,
    )
    fill_header(msg.header, stamp, topics.SCAN_FRAME)
    fill_pose(msg.world_pose, state)
    msg.ranges.extend(sim.scan_ranges(state, angles, room, RANGE_MAX).tolist())
    msg.intensities.extend([0.0] * SCAN_BEAMS)
    return msg


def camera_info_message(stamp: float) -> Any:
    """A pinhole camera without distortion whose focal length matches CAMERA_FOV."""
    focal = (IMAGE_WIDTH / 2.0) / math.tan(CAMERA_FOV / 2.0)
    cx, cy = IMAGE_WIDTH / 2.0, IMAGE_HEIGHT / 2.0
    msg = GzCameraInfo(width=IMAGE_WIDTH, height=IMAGE_HEIGHT)
    fill_header(msg.header, stamp, topics.CAMERA_FRAME)
    msg.distortion.k.extend([0.0] * 5)
    msg.intrinsics.k.extend([focal, 0.0, cx, 0.0, focal, cy, 0.0, 0.0, 1.0])
    msg.projection.p.extend([focal, 0.0, cx, 0.0, 0.0, focal, cy, 0.0, 0.0, 0.0, 1.0, 0.0])
    msg.rectification_matrix.extend(diagonal(1.0))
    return msg


def image_message(state: sim.RobotState, stamp: float, frame: int) -> Any:
    pixels = sim.camera_image(state.yaw, frame, IMAGE_WIDTH, IMAGE_HEIGHT, CAMERA_FOV)
    msg = GzImage(
        width=IMAGE_WIDTH,
        height=IMAGE_HEIGHT,
        step=IMAGE_WIDTH * 3,
        pixel_format_type=RGB_INT8,
        data=pixels.tobytes(),
    )
    fill_header(msg.header, stamp, topics.CAMERA_FRAME)
    return msg


class World:
    """The robot, its command, and one publisher per sensor topic on ``node``."""

    def __init__(self, node: GzNode, room: sim.Room | None = None) -> None:
        self.room = room or sim.Room()
        self.state = sim.RobotState()
        self._command = (0.0, 0.0)
        self._lock = threading.Lock()
        self._steps = 0
        self._last_time: float | None = None
        self._cmd_sub = node.subscribe_typed(topics.CMD_VEL, GzTwist, self._on_cmd_vel)
        builders: dict[str, tuple[int, Callable[[float], Any]]] = {
            topics.CLOCK: (CLOCK_PERIOD, clock_message),
            topics.IMU: (IMU_PERIOD, lambda now: imu_message(self.state, now)),
            topics.ODOM: (ODOM_PERIOD, lambda now: odometry_message(self.state, now)),
            topics.TF: (ODOM_PERIOD, lambda now: tf_message(self.state, now)),
            topics.JOINT_STATES: (
                ODOM_PERIOD,
                lambda now: joint_states_message(self.state, now),
            ),
            topics.SCAN: (SCAN_PERIOD, lambda now: scan_message(self.state, now, self.room)),
            topics.CAMERA_INFO: (CAMERA_PERIOD, camera_info_message),
            topics.CAMERA_IMAGE: (
                CAMERA_PERIOD,
                lambda now: image_message(self.state, now, self._steps // CAMERA_PERIOD),
            ),
        }
        #: (period in steps, publisher, message builder) for every topic.
        self._schedule: list[tuple[int, Publisher, Callable[[float], Any]]] = []
        for topic in topics.GZ_TO_ROS:
            period, build = builders[topic.name]
            self._schedule.append((period, node.advertise(topic.name, topic.gz_type), build))

    def _on_cmd_vel(self, msg: Any, _info: MessageInfo) -> None:
        with self._lock:
            self._command = (msg.linear.x, msg.angular.z)

    def tick(self, now: float) -> None:
        """Advance the physics to wall time ``now`` and publish what is due at this step."""
        dt = 0.0 if self._last_time is None else min(max(now - self._last_time, 0.0), MAX_DT)
        self._last_time = now
        with self._lock:
            linear, angular = self._command
        self.state = sim.step(self.state, linear, angular, dt, self.room)
        for period, publisher, build in self._schedule:
            if self._steps % period == 0 and publisher.has_connections():
                publisher.publish(build(now))
        self._steps += 1

    def run(self, stop: StopSignal) -> None:
        """Step at STEP_HZ on the wall clock until ``stop`` is requested."""
        period = 1.0 / STEP_HZ
        next_step = time.monotonic()
        while not stop.requested:
            self.tick(time.time())
            next_step += period
            delay = next_step - time.monotonic()
            if delay < -MAX_DT:
                next_step = time.monotonic()
            stop.wait(max(delay, 0.0))


def main() -> int:
    with StopSignal() as stop, create_gz_node() as node:
        world = World(node)
        print(f"READY: demo world publishing {len(topics.GZ_TO_ROS)} topics", flush=True)
        world.run(stop)
    print(f"world stopped at x={world.state.x:.3f} y={world.state.y:.3f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
