"""Two simulated hosts on this machine: network namespaces joined by a veth pair.

One namespace plays the simulator host, the other the ROS host; each has its loopback and
one end of the veth, and nothing else, so no packet of theirs can reach a real interface.
They use different multicast groups for Gazebo discovery, as hosts on two networks would:
only unicast (``GZ_RELAY``) discovery crosses, and the link can be taken down and up again.
Needs root (creating namespaces and links); tests call :func:`require_namespaces`.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import pytest

#: Discovery groups of the two hosts (docs/protocol-zmq-discovery.md §2.2, §2.7).
SIM_GROUP = "239.255.0.71"
ROS_GROUP = "239.255.0.72"


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True, timeout=10)


def namespaces_missing() -> str | None:
    """Why namespaces cannot be made here, or None."""
    if os.geteuid() != 0:
        return "creating network namespaces needs root"
    try:
        _ip("netns", "list")
    except (OSError, subprocess.CalledProcessError) as error:
        return f"the ip tool cannot list namespaces: {error}"
    return None


def require_namespaces() -> None:
    """Skip without namespaces; under CI=true that is a failure (CI runs as root)."""
    missing = namespaces_missing()
    if missing is None:
        return
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(missing)
    pytest.skip(missing)


@dataclass(frozen=True)
class Host:
    """One namespace, its end of the link, and its address."""

    namespace: str
    link: str
    address: str
    group: str

    def command(self, args: Sequence[str]) -> list[str]:
        """``args`` run inside this host's namespace."""
        return ["ip", "netns", "exec", self.namespace, *args]

    def gazebo_env(
        self, partition: str, relay: str = "", base: Mapping[str, str] | None = None
    ) -> dict[str, str]:
        """Gazebo Transport settings of this host (both GZ_ and IGN_ names, for every line)."""
        env = dict(os.environ if base is None else base)
        values = {
            "IP": self.address,
            "PARTITION": partition,
            "DISCOVERY_MULTICAST_IP": self.group,
            "RELAY": relay,
        }
        for name, value in values.items():
            for prefix in ("GZ_", "IGN_"):
                if value:
                    env[prefix + name] = value
                else:
                    env.pop(prefix + name, None)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        return env

    def set_link(self, up: bool) -> None:
        _ip("-n", self.namespace, "link", "set", self.link, "up" if up else "down")


@dataclass(frozen=True)
class TwoHosts:
    sim: Host
    ros: Host


@contextmanager
def two_hosts(tag: str) -> Iterator[TwoHosts]:
    """A simulator host and a ROS host, deleted on exit; ``tag`` (a few letters or digits)
    keeps the names unique on this machine. Namespaces do not share routes, so every pair
    can use the same addresses."""
    sim = Host(f"rgbp-sim-{tag}", f"rgbps{tag}"[:15], "10.77.0.1", SIM_GROUP)
    ros = Host(f"rgbp-ros-{tag}", f"rgbpr{tag}"[:15], "10.77.0.2", ROS_GROUP)
    made: list[str] = []
    try:
        for host in (sim, ros):
            _ip("netns", "add", host.namespace)
            made.append(host.namespace)
            _ip("-n", host.namespace, "link", "set", "lo", "up")
        _ip("link", "add", sim.link, "type", "veth", "peer", "name", ros.link)
        for host in (sim, ros):
            _ip("link", "set", host.link, "netns", host.namespace)
            _ip("-n", host.namespace, "addr", "add", f"{host.address}/24", "dev", host.link)
            _ip("-n", host.namespace, "link", "set", host.link, "up")
            # Multicast leaves through the link (gz sends it on GZ_IP's interface).
            _ip("-n", host.namespace, "route", "add", "224.0.0.0/4", "dev", host.link)
        yield TwoHosts(sim, ros)
    finally:
        for namespace in made:
            subprocess.run(["ip", "netns", "del", namespace], check=False, capture_output=True)
