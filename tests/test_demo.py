"""The built-in demo: its pure physics and sensors, its report, and one whole run end to end.

The end-to-end test runs ``python -m ros_gz_bridge_py.demo`` as ``make demo`` does (world,
parameter_bridge, image_bridge and the rclpy client; loopback settings from conftest.py) and
reads its output like a newcomer would.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ros_gz_bridge_py.demo import __main__ as demo_main
from ros_gz_bridge_py.demo import sim
from ros_gz_bridge_py.demo.report import Pose2D, Row, TopicStats, verdict
from ros_gz_bridge_py.demo.topics import GZ_TO_ROS
from testing.gzpeer import start_process, stop_processes

ROOM = sim.Room()
BRIDGED = (
    "/clock",
    "/joint_states",
    "/odom",
    "/tf",
    "/imu",
    "/scan",
    "/camera/camera_info",
    "/camera/image_raw",
)
ROW = re.compile(r"^(/\S+)\s+(\S+)\s+(\d+\.\d)\s+(\S+)\s+(\d+)$")
POSE = re.compile(r"^robot pose \(odom\): x=(\S+) m\s+y=(\S+) m\s+yaw=\s*(\S+) deg$")
DEMO_SECONDS = 20
#: Start-up waits (20 s + 30 s) + DEMO_SECONDS + stopping the children, with room to spare.
DEMO_TIMEOUT = 150


def drive(state: sim.RobotState, linear: float, angular: float, seconds: float) -> sim.RobotState:
    steps = round(seconds * 100)
    for _ in range(steps):
        state = sim.step(state, linear, angular, seconds / steps, ROOM)
    return state


def test_straight_drive_moves_along_the_heading() -> None:
    start = sim.RobotState(yaw=math.pi / 2)
    end = drive(start, 0.2, 0.0, 2.0)
    assert end.x == pytest.approx(0.0, abs=1e-9)
    assert end.y == pytest.approx(0.4)
    expected_wheel = 0.4 / sim.WHEEL_RADIUS
    assert end.left_wheel == pytest.approx(expected_wheel)
    assert end.right_wheel == pytest.approx(expected_wheel)


def test_constant_command_drives_a_closed_circle() -> None:
    linear, angular = 0.2, 0.4
    half = drive(sim.RobotState(), linear, angular, math.pi / angular)
    full = drive(half, linear, angular, math.pi / angular)
    # Half a turn ends on the far side of the circle, a full turn back at the start.
    assert (half.x, half.y) == pytest.approx((0.0, 2 * linear / angular), abs=1e-9)
    assert abs(half.yaw) == pytest.approx(math.pi)
    assert (full.x, full.y, full.yaw) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)


def test_turning_in_place_spins_the_wheels_in_opposite_directions() -> None:
    end = drive(sim.RobotState(), 0.0, 1.0, 1.0)
    assert (end.x, end.y, end.yaw) == pytest.approx((0.0, 0.0, 1.0))
    assert end.left_wheel == pytest.approx(-end.right_wheel)
    assert end.right_wheel == pytest.approx(sim.WHEEL_SEPARATION / 2 / sim.WHEEL_RADIUS)


def test_the_room_stops_the_robot() -> None:
    end = drive(sim.RobotState(), 1.0, 0.0, 10.0)
    assert end.x == pytest.approx(ROOM.half_x - sim.ROBOT_RADIUS)


def test_yaw_quaternion_is_a_unit_rotation_about_z() -> None:
    x, y, z, w = sim.yaw_quaternion(math.pi / 2)
    assert (x, y) == (0.0, 0.0)
    assert (z, w) == pytest.approx((math.sqrt(0.5), math.sqrt(0.5)))


def beam(ranges: np.ndarray, angles: np.ndarray, angle: float) -> float:
    return float(ranges[int(np.argmin(np.abs(angles - angle)))])


def test_scan_sees_the_walls_and_the_pillar() -> None:
    angles = sim.scan_angles(360)
    ranges = sim.scan_ranges(sim.RobotState(), angles, ROOM, range_max=10.0)
    assert ranges.shape == (360,)
    assert beam(ranges, angles, 0.0) == pytest.approx(ROOM.half_x)
    assert beam(ranges, angles, math.pi / 2) == pytest.approx(ROOM.half_y)
    assert beam(ranges, angles, math.pi) == pytest.approx(ROOM.half_x)
    pillar_angle = math.atan2(ROOM.pillar_y, ROOM.pillar_x) % math.tau
    pillar_distance = math.hypot(ROOM.pillar_x, ROOM.pillar_y) - ROOM.pillar_radius
    assert beam(ranges, angles, pillar_angle) == pytest.approx(pillar_distance, abs=0.01)
    assert np.all(np.isfinite(ranges))
    assert np.all(ranges > 0)


def test_scan_angles_are_relative_to_the_heading() -> None:
    angles = sim.scan_angles(4)
    facing_up = sim.scan_ranges(sim.RobotState(yaw=math.pi / 2), angles, ROOM, range_max=10.0)
    assert facing_up[0] == pytest.approx(ROOM.half_y)
    assert facing_up[1] == pytest.approx(ROOM.half_x)


def test_scan_reports_inf_past_range_max() -> None:
    near_wall = sim.RobotState(x=-ROOM.half_x + 0.5)
    ranges = sim.scan_ranges(near_wall, np.array([0.0, math.pi]), ROOM, range_max=3.5)
    assert ranges[0] == math.inf
    assert ranges[1] == pytest.approx(0.5)


def test_camera_image_is_rgb8_and_moves() -> None:
    first = sim.camera_image(0.0, 0, 160, 120, 1.0)
    assert first.shape == (120, 160, 3)
    assert first.dtype == np.uint8
    assert not np.array_equal(first, sim.camera_image(0.0, 1, 160, 120, 1.0))
    assert not np.array_equal(first, sim.camera_image(0.5, 0, 160, 120, 1.0))


def test_topic_stats_rate_and_latency() -> None:
    stats = TopicStats(GZ_TO_ROS[0])
    stats.window(100.0)
    for i in range(10):
        stats.record(100.0 + 0.1 * i, 100.0 + 0.1 * i - 0.002)
    row = stats.window(101.0)
    assert row.rate_hz == pytest.approx(10.0)
    assert row.latency_ms == pytest.approx(2.0)
    assert stats.overall().rate_hz == pytest.approx(10.0)
    assert stats.window(102.0).rate_hz == 0.0


def test_verdict_needs_every_topic_and_a_moving_robot() -> None:
    rows = [Row(topic, 10.0, 1.0, 100) for topic in GZ_TO_ROS]
    start, moved = Pose2D(0.0, 0.0, 0.0), Pose2D(0.5, 0.1, 0.3)
    assert verdict(rows, start, moved).passed
    assert not verdict(rows, start, start).passed
    silent = [*rows[:-1], Row(GZ_TO_ROS[-1], 0.0, None, 0)]
    result = verdict(silent, start, moved)
    assert not result.passed
    assert "/camera/image_raw" in result.line


def run_demo() -> tuple[int | None, str]:
    """One whole demo run: its exit status and output (stopped by force after DEMO_TIMEOUT)."""
    env = {**os.environ, "DEMO_SECONDS": str(DEMO_SECONDS)}
    proc = start_process([sys.executable, "-m", "ros_gz_bridge_py.demo"], env)
    try:
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(DEMO_TIMEOUT)
    finally:
        stop_processes()
    return proc.returncode, proc.output()


def rows_by_topic(lines: list[str]) -> dict[str, tuple[float, int]]:
    """(rate, count) per topic from table lines."""
    found = {}
    for line in lines:
        if match := ROW.match(line):
            found[match[1]] = (float(match[3]), int(match[5]))
    return found


@pytest.mark.parametrize(("argv", "status"), [(["--help"], 0), (["-h"], 0), (["--fast"], 2)])
def test_an_argument_gets_the_help_or_one_line_not_a_demo(
    argv: list[str], status: int, capsys: pytest.CaptureFixture[str]
) -> None:
    """``python -m ros_gz_bridge_py.demo --help`` started the whole demo."""
    assert demo_main.main(argv) == status
    out, err = capsys.readouterr()
    if status == 0:
        assert "DEMO_SECONDS" in out
        assert err == ""
    else:
        assert err == "demo: takes no arguments, not '--fast' (-h tells more)\n"


@pytest.mark.slow
@pytest.mark.ros
def test_demo_bridges_every_topic_and_drives_the_robot() -> None:
    status, output = run_demo()
    assert status == 0, output
    lines = output.splitlines()
    summary_at = next(i for i, line in enumerate(lines) if line.startswith("=== summary"))
    live, summary = lines[:summary_at], lines[summary_at:]

    last_refresh = max(i for i, line in enumerate(live) if line.startswith("--- "))
    for table in (live[last_refresh:], summary):
        rows = rows_by_topic(table)
        for topic in BRIDGED:
            rate, count = rows.get(topic, (0.0, 0))
            shown = "\n".join(table)
            assert count > 0, f"no {topic} messages in:\n{shown}"
            assert rate > 0, f"{topic} at rate 0 in:\n{shown}"

    poses = [tuple(map(float, m.groups())) for line in live if (m := POSE.match(line))]
    assert len(poses) >= 2, output
    assert any(a != b for a, b in itertools.pairwise(poses)), output
    assert any(line.startswith("PASS:") for line in summary), output

    pids = [int(m[1]) for line in lines if (m := re.search(r"\bpid (\d+):", line))]
    assert len(pids) == 3, output
    leftovers = [pid for pid in pids if Path(f"/proc/{pid}").exists()]
    assert not leftovers, f"children still running: {leftovers}"
