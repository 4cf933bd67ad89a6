"""``bridge_node`` as ros_gz_bridge's launch file starts it, without ROS launch: the real
executable, Fortress peers (Debian ign-transport 11) and an rclpy checker.

ros_gz's launch file runs ``bridge_node --ros-args --log-level L --ros-args -r __node:=NAME
-r __ns:=/NS --params-file <file with config_file>``; this runs the same command line with the
parameters given as ``-p``, plus a topic argument that bridge_node must name and not bridge.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from testing.e2e_harness import RUN_TIMEOUT, ProcessGroup, RosChecker, wait_all
from testing.gzpeer import PeerProcess, wait_for_line
from tests.bridge.e2e_values import ODOMETRY, mismatches

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

#: The console script of the venv running the tests (beside the interpreter).
BRIDGE_NODE = Path(sys.prefix) / "bin" / "bridge_node"
SEED_CONFIG = Path("/work/shared/data/configs/turtlebot3_waffle_bridge.yaml")
SEED_ENTRIES = 8
STRAY = "/stray@std_msgs/msg/String[gz.msgs.StringMsg"


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    started = ProcessGroup()
    yield started
    started.stop()


def stop_with_sigint(proc: PeerProcess) -> str:
    proc.send_signal(signal.SIGINT)
    proc.wait(RUN_TIMEOUT)
    output = proc.output()
    assert proc.returncode == 0, output
    assert "Traceback" not in output, output
    return output


def test_bridge_node_renamed_and_namespaced_bridges_its_config_file(group: ProcessGroup) -> None:
    bridge = group.start(
        [
            str(BRIDGE_NODE), STRAY,
            "--ros-args", "--log-level", "info",
            "--ros-args", "-r", "__node:=b", "-r", "__ns:=/tb3",
            "-p", f"config_file:={SEED_CONFIG}", "-p", "expand_gz_topic_names:=true",
        ]
    )  # fmt: skip
    group.peer(*ODOMETRY.peer_pub_args("/tb3/odom"))
    checker = RosChecker(group, [("/tb3/odom", "nav_msgs/msg/Odometry")])
    wait_all(
        {
            "odom": lambda: any(
                not mismatches(ODOMETRY.ros, msg) for msg in checker.messages("/tb3/odom")
            )
        },
        RUN_TIMEOUT,
    )
    received = checker.messages("/tb3/odom")
    assert any(not mismatches(ODOMETRY.ros, msg) for msg in received), bridge.output()
    output = stop_with_sigint(bridge)
    lines = output.splitlines()
    created = [line for line in lines if "[tb3.b]: Creating" in line]
    assert len(created) == SEED_ENTRIES, output
    assert any("/tb3/odom (gz.msgs.Odometry)" in line for line in created), output
    assert f"bridge_node: not bridged: {STRAY} (bridge_node reads only parameters" in output
    assert not any("/stray" in line for line in created), output


def test_bridge_node_without_parameters_runs_and_says_what_it_bridges(
    group: ProcessGroup,
) -> None:
    bridge = group.start([str(BRIDGE_NODE)])
    wait_for_line(bridge, r"\[ros_gz_bridge\]: No bridges are running", RUN_TIMEOUT)
    stop_with_sigint(bridge)


def test_bridge_node_help() -> None:
    done = subprocess.run(
        [str(BRIDGE_NODE), "-h"], capture_output=True, text=True, timeout=RUN_TIMEOUT, check=False
    )
    assert done.returncode == 0, done.stderr
    assert "bridge_node --ros-args -p config_file:=<bridge.yaml>" in done.stdout
