"""A process killed before it closes its DDS participant leaves its Fast DDS shared-memory
segment behind (64 MB with the bridge's profile); the next bridge removes it, and says so.

Real components: an rclpy process with the bridge's Fast DDS profile, killed with SIGKILL, and
a parameter_bridge started afterwards.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

from ros_gz_bridge_py.ros.speed import PROFILE, SHM_DIR, ZOMBIE_MIN_AGE
from tests.bridge.behaviour_harness import bridge_command
from tests.gzpeer import start_process, unique_name, wait_for_line

WAIT = 20.0
#: An rclpy node that publishes once, so its shared-memory segment exists, then waits.
ROS_NODE = """
import time, rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node("zombie_to_be")
node.create_publisher(String, "/zombie_to_be", 10).publish(String(data="x"))
print("UP", flush=True)
time.sleep(60)
"""


def mapped_segments(pid: int) -> set[Path]:
    """The Fast DDS segments process ``pid`` maps."""
    with open(f"/proc/{pid}/maps") as maps:
        paths = {line.split()[-1] for line in maps if "/dev/shm/fastrtps_" in line}
    return {Path(path) for path in paths if "_port" not in path}


def test_a_killed_processs_segment_is_removed_by_the_next_bridge() -> None:
    env = {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(PROFILE)}
    node = start_process([sys.executable, "-c", ROS_NODE], env)
    wait_for_line(node, "^UP$", timeout=WAIT)
    segments = mapped_segments(node.pid)
    assert segments, "the rclpy process maps no Fast DDS segment"
    assert max(segment.stat().st_size for segment in segments) >= 64 * 2**20  # our profile
    os.kill(node.pid, signal.SIGKILL)
    node.wait(timeout=WAIT)
    time.sleep(0.5)
    assert all(segment.exists() for segment in segments), "Fast DDS removed them itself"
    # As old as a zombie must be (a younger unlocked lock may be a segment being made).
    then = time.time() - ZOMBIE_MIN_AGE - 1
    for segment in segments:
        os.utime(SHM_DIR / f"{segment.name}_el", (then, then))
    topic = unique_name("zombie")
    bridge = start_process(bridge_command(f"{topic}@std_msgs/msg/String@gz.msgs.StringMsg"))
    try:
        line = wait_for_line(bridge, r"removed (\d+) Fast DDS shared-memory segments", WAIT)
        assert int(line[1]) >= len(segments)
        assert not any(segment.exists() for segment in segments)
        assert not any(Path(f"{segment}_el").exists() for segment in segments)
        wait_for_line(bridge, r"\]: Creating ", timeout=WAIT)  # and it runs on
    finally:
        bridge.stop()
