"""A process killed before it closes its DDS participant leaves its Fast DDS shared-memory
segment behind (64 MB with the bridge's profile); the next bridge removes it, and says so, and
leaves the segments of live processes alone.

Real components: two rclpy processes with the bridge's Fast DDS profile, one killed with
SIGKILL, and a parameter_bridge started afterwards.
"""

from __future__ import annotations

import os
import re
import signal
import sys
import time
from pathlib import Path

from ros_gz_bridge_py.ros.speed import PROFILE, SHM_DIR, ZOMBIE_MIN_AGE
from testing.behaviour_harness import bridge_command
from testing.gzpeer import start_process, unique_name, wait_for_line

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


def owned_segments(pid: int) -> set[Path]:
    """The Fast DDS segments process ``pid`` owns: those whose lock file it holds open (a
    process also maps the segments of the peers it reads from)."""
    owned = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        target = os.readlink(fd)
        if re.fullmatch(r"/dev/shm/fastrtps_[0-9a-z]{16}_el", target):
            owned.add(Path(target.removesuffix("_el")))
    return owned


def make_old(segments: set[Path]) -> None:
    """Date the segments' lock files back as far as a zombie's must be (a younger unlocked lock
    may be a segment being made), so that only the lock itself can spare them."""
    then = time.time() - ZOMBIE_MIN_AGE - 1
    for segment in segments:
        os.utime(SHM_DIR / f"{segment.name}_el", (then, then))


def test_a_killed_processs_segment_is_removed_by_the_next_bridge() -> None:
    env = {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(PROFILE)}
    node = start_process([sys.executable, "-c", ROS_NODE], env)
    alive = start_process([sys.executable, "-c", ROS_NODE], env)
    wait_for_line(node, "^UP$", timeout=WAIT)
    wait_for_line(alive, "^UP$", timeout=WAIT)
    segments, live_segments = owned_segments(node.pid), owned_segments(alive.pid)
    assert live_segments
    make_old(live_segments)
    assert segments, "the rclpy process maps no Fast DDS segment"
    assert max(segment.stat().st_size for segment in segments) >= 64 * 2**20  # our profile
    os.kill(node.pid, signal.SIGKILL)
    node.wait(timeout=WAIT)
    time.sleep(0.5)
    assert all(segment.exists() for segment in segments), "Fast DDS removed them itself"
    make_old(segments)
    topic = unique_name("zombie")
    bridge = start_process(bridge_command(f"{topic}@std_msgs/msg/String@gz.msgs.StringMsg"))
    try:
        line = wait_for_line(bridge, r"removed (\d+) Fast DDS shared-memory segments", WAIT)
        assert int(line[1]) >= len(segments)
        assert not any(segment.exists() for segment in segments)
        assert not any(Path(f"{segment}_el").exists() for segment in segments)
        assert all(segment.exists() for segment in live_segments)
        wait_for_line(bridge, r"\]: Creating ", timeout=WAIT)  # and it runs on
    finally:
        bridge.stop()
        alive.stop()
