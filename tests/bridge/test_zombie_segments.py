"""A process killed before it closes its DDS participant leaves its Fast DDS shared-memory
segment behind (64 MB with the bridge's profile); the next bridge removes it, and says so, and
leaves the segments of live processes alone.

Real components: two rclpy processes with the bridge's Fast DDS profile, one killed with
SIGKILL, and a parameter_bridge started afterwards. Where the test may make a mount namespace
(root), the three run in one whose /dev/shm is a tmpfs of its own: any other bridge on the host
(another test session's) would otherwise remove the test's zombie first, which a busy shared
machine showed.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.ros.speed import PROFILE, ZOMBIE_MIN_AGE
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


class SharedMemory:
    """Where the test's processes keep their Fast DDS segments: a mount namespace with a tmpfs
    at /dev/shm, held open by a sleeping process, or the host's /dev/shm where none can be
    made."""

    def __init__(self) -> None:
        self.holder: subprocess.Popen[str] | None = None
        setup = "mount -t tmpfs -o size=1g tmpfs /dev/shm && echo READY && exec sleep 600"
        try:
            self.holder = subprocess.Popen(
                ["unshare", "--mount", "--propagation", "private", "sh", "-c", setup],
                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
            )  # fmt: skip
        except OSError:
            return
        assert self.holder.stdout is not None
        if self.holder.stdout.readline().strip() != "READY":  # not allowed here
            self.holder.wait()
            self.holder = None

    def command(self, command: list[str]) -> list[str]:
        """``command`` run in the namespace (nsenter execs it: the pid is the command's)."""
        if self.holder is None:
            return command
        return ["nsenter", f"--mount=/proc/{self.holder.pid}/ns/mnt", "--", *command]

    def seen_here(self, path: str) -> Path:
        """``path``, as the namespace's processes name it, from this process."""
        if self.holder is None:
            return Path(path)
        return Path(f"/proc/{self.holder.pid}/root") / path.lstrip("/")

    def close(self) -> None:
        if self.holder is not None:
            self.holder.kill()
            self.holder.wait()


@pytest.fixture
def shm() -> Iterator[SharedMemory]:
    memory = SharedMemory()
    yield memory
    memory.close()


def owned_segments(shm: SharedMemory, pid: int) -> set[Path]:
    """The Fast DDS segments process ``pid`` owns: those whose lock file it holds open (a
    process also maps the segments of the peers it reads from)."""
    owned = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        target = os.readlink(fd)
        if re.fullmatch(r"/dev/shm/fastrtps_[0-9a-z]{16}_el", target):
            owned.add(shm.seen_here(target.removesuffix("_el")))
    return owned


def make_old(segments: set[Path]) -> None:
    """Date the segments' lock files back as far as a zombie's must be (a younger unlocked lock
    may be a segment being made), so that only the lock itself can spare them."""
    then = time.time() - ZOMBIE_MIN_AGE - 1
    for segment in segments:
        os.utime(segment.with_name(f"{segment.name}_el"), (then, then))


def test_a_killed_processs_segment_is_removed_by_the_next_bridge(shm: SharedMemory) -> None:
    env = {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(PROFILE)}
    node = start_process(shm.command([sys.executable, "-c", ROS_NODE]), env)
    alive = start_process(shm.command([sys.executable, "-c", ROS_NODE]), env)
    wait_for_line(node, "^UP$", timeout=WAIT)
    wait_for_line(alive, "^UP$", timeout=WAIT)
    segments, live_segments = owned_segments(shm, node.pid), owned_segments(shm, alive.pid)
    assert live_segments
    make_old(live_segments)
    assert segments, "the rclpy process maps no Fast DDS segment"
    assert max(segment.stat().st_size for segment in segments) >= 64 * 2**20  # our profile
    os.kill(node.pid, signal.SIGKILL)
    node.wait(timeout=WAIT)
    assert all(segment.exists() for segment in segments), "Fast DDS removed them itself"
    make_old(segments)
    topic = unique_name("zombie")
    bridge = start_process(
        shm.command(bridge_command(f"{topic}@std_msgs/msg/String@gz.msgs.StringMsg"))
    )
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
