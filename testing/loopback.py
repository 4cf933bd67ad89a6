"""Addresses and environments that keep a run's traffic on this host."""

from __future__ import annotations

import json
import os
import socket
from collections.abc import Sequence


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def zenoh_override(
    mode: str = "peer", listen: Sequence[str] = (), connect: Sequence[str] = ()
) -> str:
    """``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE`` for one process: ``mode`` (peer, client), explicit
    endpoints only, no multicast or gossip scouting."""
    entries = {
        "mode": json.dumps(mode),
        "scouting/multicast/enabled": "false",
        "scouting/gossip/enabled": "false",
        "listen/endpoints": json.dumps(list(listen)),
        "connect/endpoints": json.dumps(list(connect)),
    }
    return ";".join(f"{key}={value}" for key, value in entries.items())


def zenoh_env(mode: str, listen: list[str], connect: list[str]) -> dict[str, str]:
    """Our environment plus the gz-transport 15 Zenoh settings of :func:`zenoh_override`."""
    return dict(
        os.environ,
        GZ_TRANSPORT_IMPLEMENTATION="zenoh",
        GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE=zenoh_override(mode, listen, connect),
    )
