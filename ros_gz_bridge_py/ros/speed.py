"""The Fast DDS shared-memory profile the executables apply before ``rclpy.init``.

Fast DDS's built-in shared-memory segment is 0.5 MB, so every camera image leaves it for
fragmented UDP; measured on the project machines (docs/environment.md §2) a 64 MB segment lifts
1080p rclpy throughput from ~40 to ~270 msg/s. Its writers also ignore NACKs for 20 ms after a
send, so that Fast DDS's event thread is not woken for every sample (same section). The
profile (``resources/fastdds_shm_profile.xml``) is applied only when the user has not chosen
otherwise: the RMW is Fast DDS (unset or ``rmw_fastrtps_cpp``), neither
``FASTRTPS_DEFAULT_PROFILES_FILE`` nor ``FASTDDS_DEFAULT_PROFILES_FILE`` is set, and it is not
switched off (``enabled=False``; the executables' ``ROS_GZ_BRIDGE_FASTDDS_PROFILE=off``, read by
:mod:`ros_gz_bridge_py.app.settings`).

A process killed before it closes its participant leaves its segment in ``/dev/shm``: with this
profile 64 MB of memory each, until reboot. Where the profile is applied, the executables first
remove the segments whose owner is gone (:func:`remove_zombie_segments`, as ``fastdds shm
clean`` does; docs/environment.md §2).

The profile replaces Fast DDS's built-in transports with SHM + UDPv4. With
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` / ``ROS_LOCALHOST_ONLY=1`` the bridge plus an rclpy
subscriber were checked with ``tcpdump -i eth0 udp`` to send nothing off the host.
"""

from __future__ import annotations

import fcntl
import logging
import os
import re
import time
from collections.abc import Mapping, MutableMapping
from dataclasses import dataclass
from pathlib import Path

PROFILE = Path(__file__).resolve().parent / "resources" / "fastdds_shm_profile.xml"
PROFILE_ENVS = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")
FAST_DDS_RMW = "rmw_fastrtps_cpp"

_LOG = logging.getLogger(__name__)

#: Where Fast DDS keeps its shared memory on Linux. Each segment ``fastrtps_<16 characters>``
#: has a lock file ``<segment>_el`` that its owner holds (``flock``) as long as it lives.
SHM_DIR = Path("/dev/shm")  # noqa: S108 - Fast DDS's fixed place, not a temporary file
_SEGMENT_LOCK = re.compile(r"^fastrtps_[0-9a-z]{16}_el$")
#: A lock file younger than this may belong to a segment being made (created, then locked).
ZOMBIE_MIN_AGE = 10.0


@dataclass(frozen=True)
class ProfileDecision:
    """Whether to apply the profile, and why (for the log)."""

    apply: bool
    reason: str


def decide(env: Mapping[str, str], *, enabled: bool) -> ProfileDecision:
    """The decision for the environment ``env`` (no side effects); ``enabled`` False: the user
    switched our profile off."""
    if not enabled:
        return ProfileDecision(False, "switched off by ROS_GZ_BRIDGE_FASTDDS_PROFILE")
    rmw = env.get("RMW_IMPLEMENTATION", "").strip()
    if rmw and rmw != FAST_DDS_RMW:
        return ProfileDecision(False, f"RMW_IMPLEMENTATION={rmw} is not Fast DDS")
    for name in PROFILE_ENVS:
        if env.get(name):
            return ProfileDecision(False, f"{name} is set by the user")
    return ProfileDecision(True, f"Fast DDS with no user profile: applying {PROFILE}")


@dataclass(frozen=True)
class Removed:
    """What :func:`remove_zombie_segments` removed."""

    segments: int
    size: int

    def describe(self) -> str:
        return (
            f"removed {self.segments} Fast DDS shared-memory segments "
            f"({self.size / 2**20:.0f} MB) left by processes that exited without closing them"
        )


def remove_zombie_segments(shm_dir: Path = SHM_DIR, min_age: float = ZOMBIE_MIN_AGE) -> Removed:
    """Remove the Fast DDS segments whose lock file no process holds, older than ``min_age``
    seconds. A segment's lock is taken (non-blocking) before it is removed, so a live one is
    never touched."""
    segments = size = 0
    try:
        names = os.listdir(shm_dir)
    except OSError:
        return Removed(0, 0)
    now = time.time()
    for name in filter(_SEGMENT_LOCK.match, names):
        lock, segment = shm_dir / name, shm_dir / name.removesuffix("_el")
        try:
            if now - lock.stat().st_mtime < min_age:
                continue
            with lock.open("ab") as held:
                fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)  # OSError: its owner lives
                found = segment.stat().st_size if segment.exists() else 0
                segment.unlink(missing_ok=True)
                lock.unlink()
        except OSError:
            continue
        segments, size = segments + 1, size + found
    return Removed(segments, size)


def apply_fastdds_profile(
    env: MutableMapping[str, str] | None = None, *, enabled: bool
) -> str | None:
    """Point Fast DDS at our profile when :func:`decide` says so; the path applied, or None.

    ``env``: the Fast DDS variables to read and set (default: the process's). Call before
    ``rclpy.init``: Fast DDS reads the variable when the first participant is made.
    """
    target = os.environ if env is None else env
    decision = decide(target, enabled=enabled)
    _LOG.debug("Fast DDS shared-memory profile: %s", decision.reason)
    if not decision.apply:
        return None
    path = str(PROFILE)
    target["FASTRTPS_DEFAULT_PROFILES_FILE"] = path
    return path
