"""Transport settings read from the environment (docs/protocol.md §1.2, §1.4).

We talk to every Gazebo line, so each variable is read under its ``GZ_`` name first and its
Fortress ``IGN_`` name second (the Garden rule). Bad port values fall back to the defaults,
as gz-transport does, with a warning instead of a failure.
"""

from __future__ import annotations

import logging
import os
import pwd
import socket
import uuid
from collections.abc import Mapping
from dataclasses import dataclass

from ros_gz_bridge_py.msgs.names import Spelling

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

DEFAULT_MULTICAST_IP = "239.255.0.7"
DEFAULT_MSG_PORT = 10317
DEFAULT_SRV_PORT = 10318
DEFAULT_HWM = 1000
MAX_PORT = 65535
#: gethostname() buffer size in gz-transport's NetUtils hostname().
_HOSTNAME_LIMIT = 200


def lookup(env: Mapping[str, str], name: str) -> str | None:
    """``GZ_<name>`` if present, else ``IGN_<name>``, else None (present-but-empty counts)."""
    for prefix in ("GZ_", "IGN_"):
        value = env.get(prefix + name)
        if value is not None:
            return value
    return None


def default_partition(env: Mapping[str, str]) -> str:
    """``<hostname>:<username>`` with the username rule of gz-transport 11.1+ / 13 (§1.2)."""
    hostname = socket.gethostname()[:_HOSTNAME_LIMIT]
    user = env.get("USER")
    if not user:
        try:
            user = pwd.getpwuid(os.getuid()).pw_name
        except KeyError:
            user = f"error-{uuid.uuid4()}"
    return f"{hostname}:{user}"


def _port(env: Mapping[str, str], name: str, default: int) -> int:
    raw = lookup(env, name)
    if raw is None:
        return default
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if not 0 <= value <= MAX_PORT:
        _LOG.warning("ignoring %s=%r: not a port number; using %d", name, raw, default)
        return default
    return value


def _positive(env: Mapping[str, str], name: str, default: int) -> int:
    raw = lookup(env, name)
    if raw is None:
        return default
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if value < 0:
        _LOG.warning("ignoring %s=%r: not a non-negative integer; using %d", name, raw, default)
        return default
    return value


@dataclass(frozen=True)
class TransportSettings:
    """Everything the environment decides about a Gazebo Transport node."""

    partition: str
    #: GZ_IP: the only discovery interface and the ZMQ bind address; None = pick one.
    ip: str | None = None
    multicast_ip: str = DEFAULT_MULTICAST_IP
    msg_port: int = DEFAULT_MSG_PORT
    srv_port: int = DEFAULT_SRV_PORT
    relays: tuple[str, ...] = ()
    rcvhwm: int = DEFAULT_HWM
    sndhwm: int = DEFAULT_HWM
    #: GZ_TRANSPORT_IMPLEMENTATION, lower-cased: "zeromq" (default) or "zenoh".
    implementation: str = "zeromq"
    #: What ZeroMQ peers of gz-transport 11/12 (Fortress, Garden: no record in their
    #: heartbeats) call their types, when nothing else tells (docs/protocol.md §9).
    legacy_spelling: Spelling = Spelling.IGNITION

    @classmethod
    def from_env(cls, env: Mapping[str, str] | None = None) -> TransportSettings:
        """Read the settings from ``env`` (default ``os.environ``)."""
        env = os.environ if env is None else env
        partition = lookup(env, "PARTITION")
        msg_port = _port(env, "DISCOVERY_MSG_PORT", DEFAULT_MSG_PORT)
        srv_port = _port(env, "DISCOVERY_SRV_PORT", DEFAULT_SRV_PORT)
        if srv_port == msg_port:
            srv_port = msg_port - 1 if msg_port == MAX_PORT else msg_port + 1
        relays = tuple(ip for ip in (lookup(env, "RELAY") or "").split(":") if ip)
        return cls(
            partition=default_partition(env) if partition is None else partition,
            ip=lookup(env, "IP") or None,
            multicast_ip=lookup(env, "DISCOVERY_MULTICAST_IP") or DEFAULT_MULTICAST_IP,
            msg_port=msg_port,
            srv_port=srv_port,
            relays=relays,
            rcvhwm=_positive(env, "TRANSPORT_RCVHWM", DEFAULT_HWM),
            sndhwm=_positive(env, "TRANSPORT_SNDHWM", DEFAULT_HWM),
            implementation=(env.get("GZ_TRANSPORT_IMPLEMENTATION") or "zeromq").lower(),
        )
