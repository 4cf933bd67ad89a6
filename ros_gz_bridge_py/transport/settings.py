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
from dataclasses import dataclass, field

from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.transport.delivery import MAX_QUEUED_BYTES

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

DEFAULT_MULTICAST_IP = "239.255.0.7"
DEFAULT_MSG_PORT = 10317
DEFAULT_SRV_PORT = 10318
DEFAULT_HWM = 1000
#: What libzmq holds for a small message waiting in a receive pipe, whatever its size: the buffer
#: it read the message into (8 KiB) when the message came alone in its read, as a simulator's
#: topics at 50 Hz to 1 kHz do (measured 8.7-9.0 kB; docs/many-topics.md, "A fleet's memory").
RECEIVE_BUFFER = 9 * 1024
#: The bytes the receive pipes of the subscriptions a node plans at its start hold together when
#: GZ_TRANSPORT_RCVHWM does not say (one channel's default ``max_queued_bytes``)...
PLANNED_RECEIVE_BYTES = MAX_QUEUED_BYTES
#: ...each pipe never fewer than this many messages (50 ms of a 1 kHz topic).
PLANNED_MIN_HWM = 50
#: Largest message accepted from the network (ours, not gz's, docs/protocol.md §1.4): a 4K
#: image of 8 bytes per pixel (66 MB) or a 1080p depth cloud of 32 bytes per point (66 MB)
#: fits twice over; a 200 MB frame does not.
DEFAULT_MAX_MESSAGE_SIZE = 128 * 1024 * 1024
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
    return _integer(env, name, default, MAX_PORT, "a port number")


def planned_rcvhwm(subscriptions: int) -> int:
    """The default receive HWM of each of ``subscriptions`` planned together: their pipes hold
    about :data:`PLANNED_RECEIVE_BYTES` of small messages (at :data:`RECEIVE_BUFFER` each),
    never more than gz-transport's 1000 a pipe nor fewer than :data:`PLANNED_MIN_HWM`. A few
    topics keep 1000; the 151 Gazebo topics of a fleet of 50 robots get 50 each, so a loop that
    falls behind holds about 70 MB in libzmq, not 1.4 GB."""
    if subscriptions <= 0:
        return DEFAULT_HWM
    fits = PLANNED_RECEIVE_BYTES // (RECEIVE_BUFFER * subscriptions)
    return min(DEFAULT_HWM, max(PLANNED_MIN_HWM, fits))


def _positive(env: Mapping[str, str], name: str, default: int, said: str = "") -> int:
    return _integer(env, name, default, None, "a non-negative integer", said=said)


def _integer(
    env: Mapping[str, str],
    name: str,
    default: int,
    highest: int | None,
    what: str,
    *,
    said: str = "",
) -> int:
    """The integer from 0 to ``highest`` in ``name``; ``default`` when unset, and with a
    warning naming the variable and its value when it is not ``what`` (``said`` is what the
    warning calls the default, when not its number)."""
    raw = lookup(env, name)
    if raw is None:
        return default
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if value < 0 or (highest is not None and value > highest):
        variable = next(prefix + name for prefix in ("GZ_", "IGN_") if prefix + name in env)
        _LOG.warning("ignoring %s=%r: not %s; using %s", variable, raw, what, said or default)
        return default
    return value


def _max_message_size(env: Mapping[str, str]) -> int:
    """GZ_TRANSPORT_MAX_MESSAGE_SIZE in bytes; 0 or a bad value: the default (with a warning
    for a bad value): there is always a limit."""
    size = _positive(env, "TRANSPORT_MAX_MESSAGE_SIZE", DEFAULT_MAX_MESSAGE_SIZE)
    return size or DEFAULT_MAX_MESSAGE_SIZE


def _credentials(env: Mapping[str, str]) -> tuple[str, str] | None:
    """(user, password) when both are set and not empty, as gz-transport requires."""
    user = lookup(env, "TRANSPORT_USERNAME")
    password = lookup(env, "TRANSPORT_PASSWORD")
    if user and password:
        return user, password
    if user or password:
        _LOG.warning(
            "GZ_TRANSPORT_USERNAME and GZ_TRANSPORT_PASSWORD must both be set (and not empty) "
            "for authentication; only one is, so it is off"
        )
    return None


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
    #: The receive HWM of the socket the native channels of small messages share
    #: (``zmq/shared_sub.py``): one pipe per publisher carries all their topics, as in a
    #: gz-transport node, so gz-transport's own mark (GZ_TRANSPORT_RCVHWM, else 1000) rather
    #: than :func:`planned_rcvhwm`'s share of one topic.
    shared_rcvhwm: int = DEFAULT_HWM
    sndhwm: int = DEFAULT_HWM
    #: GZ_TRANSPORT_MAX_MESSAGE_SIZE: larger messages are refused before they are buffered.
    max_message_size: int = DEFAULT_MAX_MESSAGE_SIZE
    #: GZ_TRANSPORT_USERNAME and GZ_TRANSPORT_PASSWORD, when both are set and not empty:
    #: ZeroMQ PLAIN authentication (docs/protocol-zmq-data.md §2.8.6); None otherwise.
    credentials: tuple[str, str] | None = field(default=None, repr=False)
    #: GZ_TRANSPORT_IMPLEMENTATION, lower-cased: "zeromq" (default) or "zenoh".
    implementation: str = "zeromq"
    #: What ZeroMQ peers of gz-transport 11/12 (Fortress, Garden: no record in their
    #: heartbeats) call their types, when nothing else tells (docs/protocol-lines.md §9).
    legacy_spelling: Spelling = Spelling.IGNITION

    @classmethod
    def from_env(
        cls, env: Mapping[str, str] | None = None, planned_subscriptions: int = 0
    ) -> TransportSettings:
        """Read the settings from ``env`` (default ``os.environ``); the default receive HWM is
        that of :func:`planned_rcvhwm` for ``planned_subscriptions``."""
        env = os.environ if env is None else env
        partition = lookup(env, "PARTITION")
        msg_port = _port(env, "DISCOVERY_MSG_PORT", DEFAULT_MSG_PORT)
        srv_port = _port(env, "DISCOVERY_SRV_PORT", DEFAULT_SRV_PORT)
        if srv_port == msg_port:
            srv_port = msg_port - 1 if msg_port == MAX_PORT else msg_port + 1
        relays = tuple(ip for ip in (lookup(env, "RELAY") or "").split(":") if ip)
        rcvhwm = _positive(env, "TRANSPORT_RCVHWM", -1, "the default")  # -1: not set
        return cls(
            partition=default_partition(env) if partition is None else partition,
            ip=lookup(env, "IP") or None,
            multicast_ip=lookup(env, "DISCOVERY_MULTICAST_IP") or DEFAULT_MULTICAST_IP,
            msg_port=msg_port,
            srv_port=srv_port,
            relays=relays,
            rcvhwm=planned_rcvhwm(planned_subscriptions) if rcvhwm < 0 else rcvhwm,
            shared_rcvhwm=DEFAULT_HWM if rcvhwm < 0 else rcvhwm,
            sndhwm=_positive(env, "TRANSPORT_SNDHWM", DEFAULT_HWM),
            max_message_size=_max_message_size(env),
            credentials=_credentials(env),
            implementation=(env.get("GZ_TRANSPORT_IMPLEMENTATION") or "zeromq").lower(),
        )
