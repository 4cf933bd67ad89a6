"""Addresses and settings that keep a test's traffic on this host."""

from __future__ import annotations

import json
import os
import socket


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def zenoh_env(mode: str, listen: list[str], connect: list[str]) -> dict[str, str]:
    """Our environment plus the gz-transport 15 Zenoh settings for one process: ``mode``
    (peer, client), explicit endpoints, no multicast or gossip scouting."""
    overrides = {
        "mode": json.dumps(mode),
        "scouting/multicast/enabled": "false",
        "scouting/gossip/enabled": "false",
        "listen/endpoints": json.dumps(listen),
        "connect/endpoints": json.dumps(connect),
    }
    return dict(
        os.environ,
        GZ_TRANSPORT_IMPLEMENTATION="zenoh",
        GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE=";".join(f"{k}={v}" for k, v in overrides.items()),
    )
