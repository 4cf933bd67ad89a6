"""The Fast DDS shared-memory profile the executables apply before ``rclpy.init``.

Fast DDS's built-in shared-memory segment is 0.5 MB, so every camera image leaves it for
fragmented UDP; measured on the project machines (docs/environment.md §2) a 64 MB segment lifts
1080p rclpy throughput from ~40 to ~270 msg/s. The profile (``resources/fastdds_shm_profile.xml``)
is applied only when the user has not chosen otherwise: the RMW is Fast DDS (unset or
``rmw_fastrtps_cpp``), neither ``FASTRTPS_DEFAULT_PROFILES_FILE`` nor
``FASTDDS_DEFAULT_PROFILES_FILE`` is set, and it is not switched off (``enabled=False``; the
executables' ``ROS_GZ_BRIDGE_FASTDDS_PROFILE=off``, read by :mod:`ros_gz_bridge_py.app.settings`).

The profile replaces Fast DDS's built-in transports with SHM + UDPv4. With
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` / ``ROS_LOCALHOST_ONLY=1`` the bridge plus an rclpy
subscriber were checked with ``tcpdump -i eth0 udp`` to send nothing off the host.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, MutableMapping
from dataclasses import dataclass
from pathlib import Path

PROFILE = Path(__file__).resolve().parent / "resources" / "fastdds_shm_profile.xml"
PROFILE_ENVS = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")
FAST_DDS_RMW = "rmw_fastrtps_cpp"

_LOG = logging.getLogger(__name__)


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
