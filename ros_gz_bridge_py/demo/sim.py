"""The demo world's physics and sensors as pure functions (no I/O, no transport).

A differential-drive robot (TurtleBot3 Waffle dimensions) in a rectangular room centred on the
origin with one round pillar. The robot's pose is integrated along exact circular arcs, so a
constant command traces a true circle; its centre is kept inside the room, which stands in for
collisions. Sensors are computed with numpy over whole arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

WHEEL_RADIUS = 0.033
WHEEL_SEPARATION = 0.287
#: Closest the robot's centre gets to a wall.
ROBOT_RADIUS = 0.2
#: Below this |angular velocity| the arc is integrated as a straight line.
_STRAIGHT = 1e-9

FloatArray = npt.NDArray[np.float64]
ImageArray = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class Room:
    """A box room ``[-half_x, half_x] x [-half_y, half_y]`` with one round pillar."""

    half_x: float = 2.5
    half_y: float = 2.0
    pillar_x: float = 1.4
    pillar_y: float = -1.0
    pillar_radius: float = 0.25


@dataclass(frozen=True)
class RobotState:
    """Pose in the odom frame, wheel joint angles (rad), and the velocities last applied."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    left_wheel: float = 0.0
    right_wheel: float = 0.0
    linear: float = 0.0
    angular: float = 0.0


def wheel_speeds(linear: float, angular: float) -> tuple[float, float]:
    """(left, right) wheel angular velocities in rad/s for a body velocity command."""
    half = angular * WHEEL_SEPARATION / 2.0
    return (linear - half) / WHEEL_RADIUS, (linear + half) / WHEEL_RADIUS


def step(state: RobotState, linear: float, angular: float, dt: float, room: Room) -> RobotState:
    """The state ``dt`` seconds later under a constant (linear, angular) command."""
    yaw = state.yaw + angular * dt
    if abs(angular) > _STRAIGHT:
        radius = linear / angular
        x = state.x + radius * (math.sin(yaw) - math.sin(state.yaw))
        y = state.y - radius * (math.cos(yaw) - math.cos(state.yaw))
    else:
        x = state.x + linear * dt * math.cos(state.yaw)
        y = state.y + linear * dt * math.sin(state.yaw)
    limit_x = room.half_x - ROBOT_RADIUS
    limit_y = room.half_y - ROBOT_RADIUS
    left, right = wheel_speeds(linear, angular)
    return replace(
        state,
        x=min(max(x, -limit_x), limit_x),
        y=min(max(y, -limit_y), limit_y),
        yaw=math.remainder(yaw, math.tau),
        left_wheel=state.left_wheel + left * dt,
        right_wheel=state.right_wheel + right * dt,
        linear=linear,
        angular=angular,
    )


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by ``yaw`` about z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def scan_angles(count: int) -> FloatArray:
    """``count`` beam angles covering a full turn, starting at 0 (as the TurtleBot3 LDS)."""
    return np.arange(count, dtype=np.float64) * (math.tau / count)


def scan_ranges(state: RobotState, angles: FloatArray, room: Room, range_max: float) -> FloatArray:
    """Distances from the robot to the walls or the pillar along each beam; +inf past range_max.

    ``angles`` are relative to the robot's heading.
    """
    directions = angles + state.yaw
    dx = np.cos(directions)
    dy = np.sin(directions)
    with np.errstate(divide="ignore"):
        wall_x = np.where(dx > 0, room.half_x - state.x, -room.half_x - state.x) / dx
        wall_y = np.where(dy > 0, room.half_y - state.y, -room.half_y - state.y) / dy
    walls = np.minimum(np.abs(wall_x), np.abs(wall_y))
    pillar = _ray_circle_distance(
        state.x - room.pillar_x, state.y - room.pillar_y, dx, dy, room.pillar_radius
    )
    ranges = np.minimum(walls, pillar)
    ranges[ranges > range_max] = np.inf
    return ranges


def _ray_circle_distance(
    ox: float, oy: float, dx: FloatArray, dy: FloatArray, radius: float
) -> FloatArray:
    """Distance along unit rays from (ox, oy) to a circle at the origin; +inf on a miss."""
    along = ox * dx + oy * dy
    discriminant = along * along - (ox * ox + oy * oy - radius * radius)
    root = np.sqrt(np.maximum(discriminant, 0.0))
    near = -along - root
    return np.where((discriminant >= 0) & (near > 0), near, np.inf)


def camera_image(yaw: float, frame: int, width: int, height: int, fov: float) -> ImageArray:
    """An rgb8 image of a rainbow-painted panorama seen at ``yaw``, with a band scrolling down.

    The colours turn as the robot turns; the band moves every frame even when it stands still.
    """
    columns = yaw + np.linspace(fov / 2.0, -fov / 2.0, width)
    hue = np.mod(columns, math.tau)[None, :] / math.tau
    channels = np.stack([hue, hue + 1.0 / 3.0, hue + 2.0 / 3.0], axis=-1)
    colours = 0.5 + 0.5 * np.cos(math.tau * channels)
    shade = np.linspace(1.0, 0.4, height)[:, None, None]
    image = (255.0 * shade * colours).astype(np.uint8)
    band = (np.arange(height) - 2 * frame) % height < height // 12
    image[band] = 255
    return image
