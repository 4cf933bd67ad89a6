"""How a Zenoh session is described to users (``transport/zenoh/config.py``)."""

from __future__ import annotations

import pytest
import zenoh

from ros_gz_bridge_py.transport.zenoh.config import describe_session


def config(**keys: str) -> zenoh.Config:
    made = zenoh.Config()
    for key, json5 in keys.items():
        made.insert_json5(key.replace("__", "/"), json5)
    return made


@pytest.mark.parametrize(
    ("mode", "listen"),
    [("client", "[]"), ("peer", '["tcp/[::]:0"]'), ("router", '["tcp/[::]:7447"]')],
)
def test_the_default_endpoints_are_those_of_the_mode(mode: str, listen: str) -> None:
    """They were Zenoh's table of every mode's: 'listen {"router": [...], "peer": [...]}'."""
    described = describe_session(config(mode=f'"{mode}"'))
    assert described == f"Zenoh {mode}, connect [], listen {listen}, multicast scouting on"


def test_endpoints_given_are_shown_as_given() -> None:
    described = describe_session(
        config(
            mode='"peer"',
            connect__endpoints='["tcp/127.0.0.1:27001"]',
            listen__endpoints='["tcp/127.0.0.1:27002"]',
            scouting__multicast__enabled="false",
        )
    )
    assert described == (
        'Zenoh peer, connect ["tcp/127.0.0.1:27001"], listen ["tcp/127.0.0.1:27002"], '
        "multicast scouting off"
    )
