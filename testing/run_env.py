"""The environment of every process of a run: a benchmark, the soak, the attacks.

Unlike the suite's (``tests/conftest.py``), it is made for processes that measure: warnings and
worse logged only, and the Fast DDS profile of the bridge executables on every ROS process.
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Mapping

from ros_gz_bridge_py.app.settings import read_switches
from ros_gz_bridge_py.ros.speed import apply_fastdds_profile

#: One Gazebo partition for a whole run, so every process of it meets the others.
PARTITION = f"bench-{os.getpid()}-{uuid.uuid4().hex[:6]}"


def run_env(backend: str = "zeromq", base: Mapping[str, str] | None = None) -> dict[str, str]:
    """Loopback only, the run's own partition (:data:`PARTITION`) and domain, warnings and
    worse logged, the bridge executables' Fast DDS profile (so a ceiling uses the same
    settings); made from ``base`` (default: this process's environment)."""
    env = dict(os.environ if base is None else base)
    env.update(
        {
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            "ROS_LOCALHOST_ONLY": "1",
            "GZ_IP": "127.0.0.1",
            "IGN_IP": "127.0.0.1",
            "GZ_PARTITION": PARTITION,
            "IGN_PARTITION": PARTITION,
            "RCUTILS_LOGGING_SEVERITY_THRESHOLD": "WARN",
        }
    )
    env.setdefault("ROS_DOMAIN_ID", str(os.getpid() % 100 + 101))
    for name in ("GZ_RELAY", "IGN_RELAY", "GZ_TRANSPORT_IMPLEMENTATION"):
        env.pop(name, None)
    apply_fastdds_profile(env, enabled=read_switches(env).fastdds_profile)
    if backend == "zenoh":
        env["GZ_TRANSPORT_IMPLEMENTATION"] = "zenoh"
    return env
