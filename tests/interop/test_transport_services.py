"""Service calls between our node and real Ignition Transport 11 processes, both directions."""

from __future__ import annotations

import re
import threading
from pathlib import Path
from typing import Any

import pytest

from ros_gz_bridge_py.errors import TransportTimeoutError
from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import ign_service, start_peer, unique_name, wait_for_line

pytestmark = pytest.mark.peer

WORLD_CONTROL = "ignition.msgs.WorldControl"
BOOLEAN = "ignition.msgs.Boolean"
STRING = "ignition.msgs.StringMsg"


def pause_request() -> bytes:
    request: bytes = message_class(WORLD_CONTROL)(pause=True, multi_step=3).SerializeToString()
    return request


def test_we_call_a_cpp_service(ign_peer: Path, gz_node: Any) -> None:
    service = unique_name("world_control")
    provider = start_peer("reply", service, WORLD_CONTROL, BOOLEAN, "30")
    wait_for_line(provider, r"^READY$")

    ok, reply = gz_node.request(service, pause_request(), WORLD_CONTROL, BOOLEAN, 10.0)

    assert ok is True
    assert message_class(BOOLEAN).FromString(reply).data is True
    wait_for_line(provider, rf"^REQUEST {WORLD_CONTROL} pause: true multi_step: 3$")


def test_we_call_a_failing_cpp_service(ign_peer: Path, gz_node: Any) -> None:
    service = unique_name("world_control_fail")
    provider = start_peer("reply", service, WORLD_CONTROL, BOOLEAN, "30", "--fail")
    wait_for_line(provider, r"^READY$")

    ok, reply = gz_node.request(service, pause_request(), WORLD_CONTROL, BOOLEAN, 10.0)

    assert (ok, reply) == (False, b"")
    wait_for_line(provider, rf"^REQUEST {WORLD_CONTROL} pause: true")


def shouting_handler(requests: list[str]) -> Any:
    """A StringMsg -> StringMsg handler answering the upper-cased text ("fail" fails)."""
    string_msg = message_class(STRING)

    def handle(request: bytes) -> tuple[bool, bytes]:
        text = string_msg.FromString(request).data
        requests.append(text)
        if text == "fail":
            return False, b""
        response: bytes = string_msg(data=text.upper()).SerializeToString()
        return True, response

    return handle


def test_cpp_peer_calls_our_service(ign_peer: Path, gz_node: Any) -> None:
    service = unique_name("shout")
    requests: list[str] = []
    gz_node.advertise_service(service, STRING, STRING, shouting_handler(requests))

    caller = start_peer("call", service, STRING, STRING, "10000", 'data: "hello"')
    wait_for_line(caller, rf'^RESPONSE {STRING} data: "HELLO"$')
    failing = start_peer("call", service, STRING, STRING, "10000", 'data: "fail"')
    wait_for_line(failing, r"^FAILED$")

    assert requests == ["hello", "fail"]


def test_cli_calls_and_lists_our_service(ign_peer: Path, gz_node: Any) -> None:
    service = unique_name("shout_cli")
    requests: list[str] = []
    gz_node.advertise_service(service, STRING, STRING, shouting_handler(requests))

    call = ign_service(
        "-s", service, "--reqtype", STRING, "--reptype", STRING, "--timeout", "10000",
        "-r", 'data: "from cli"',
    )  # fmt: skip
    listing = ign_service("-l")
    info = ign_service("-i", "-s", service)

    assert re.search(r'^data: "FROM CLI"$', call.stdout, re.MULTILINE), call.stdout
    assert requests == ["from cli"]
    assert service in listing.stdout.split()
    assert re.search(
        rf"^\s+tcp://127\.0\.0\.1:\d+, {STRING}, {STRING}$", info.stdout, re.MULTILINE
    ), info.stdout


def test_call_without_provider_times_out_once(gz_node: Any) -> None:
    service = unique_name("nobody")
    outcomes: list[tuple[bool | None, bytes]] = []
    called = threading.Event()

    def on_reply(ok: bool | None, reply: bytes) -> None:
        outcomes.append((ok, reply))
        called.set()

    gz_node.request_async(service, pause_request(), WORLD_CONTROL, BOOLEAN, 0.3, on_reply)
    with pytest.raises(TransportTimeoutError):
        gz_node.request(service, pause_request(), WORLD_CONTROL, BOOLEAN, 1.0)

    assert called.wait(5)
    assert outcomes == [(None, b"")]
