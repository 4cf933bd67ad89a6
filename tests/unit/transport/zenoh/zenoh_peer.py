"""A second Zenoh Gazebo Transport process for the ZenohGzNode tests.

Run ``python zenoh_peer.py node --mode peer --connect tcp/127.0.0.1:P`` (or ``router
--listen tcp/127.0.0.1:P``). A node reads one JSON command per line on stdin and writes one
JSON event per line on stdout: ``{"event": "done", "cmd": ...}`` after each command, plus
``msg``/``raw``/``request``/``reply``/... events from callbacks. Every session has multicast
scouting off and only the explicit loopback endpoints given.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh

from ros_gz_bridge_py.msgs import GENERIC_TYPE, message_class
from ros_gz_bridge_py.transport.api import MessageInfo
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.zenoh.config import endpoints_config
from ros_gz_bridge_py.transport.zenoh.keys import EntityKind, message_token
from ros_gz_bridge_py.transport.zenoh.node import ZenohGzNode

#: How long a peer waits for a graph condition before reporting failure.
WAIT_LIMIT = 10.0
#: How long the "slow" service handler sleeps (longer than the tests' timeouts).
SLOW_HANDLER = 1.0


class PeerNode:
    """Runs the commands of one test against a ZenohGzNode and raw Zenoh entities."""

    def __init__(self, node: ZenohGzNode) -> None:
        self.node = node
        self._out = threading.Lock()
        self._publishers: dict[str, Any] = {}
        self._keep: list[Any] = []

    def fqn(self, topic: str) -> str:
        return fully_qualified_name(self.node.partition, self.node.namespace, topic)

    def emit(self, event: str, **fields: Any) -> None:
        with self._out:
            sys.stdout.write(json.dumps({"event": event, **fields}) + "\n")
            sys.stdout.flush()

    def wait_until(self, condition: Callable[[], bool]) -> bool:
        deadline = time.monotonic() + WAIT_LIMIT
        while not condition():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def run(self, command: dict[str, Any]) -> dict[str, Any]:
        handler = getattr(self, "cmd_" + command.pop("cmd"))
        result: dict[str, Any] = handler(**command) or {}
        return result

    def cmd_advertise(self, topic: str, type: str) -> None:
        self._publishers[topic] = self.node.advertise(topic, type)

    def cmd_wait_connected(self, topic: str) -> dict[str, Any]:
        return {"ok": self.wait_until(self._publishers[topic].has_connections)}

    def cmd_publish(self, topic: str, text: str) -> None:
        self._publishers[topic].publish(message_class("gz.msgs.StringMsg")(data=text))

    def cmd_subscribe(self, topic: str, type: str) -> None:
        def on_message(payload: bytes, info: MessageInfo) -> None:
            self.emit("msg", topic=info.topic, type=info.msg_type, data=payload.hex())

        self._keep.append(self.node.subscribe(topic, on_message, type or GENERIC_TYPE))

    def cmd_raw_put(self, topic: str, payload: str, attachment: str | None) -> None:
        tag = None if attachment is None else attachment.encode()
        self.node.session.put(self.fqn(topic), bytes.fromhex(payload), attachment=tag)

    def cmd_raw_subscribe(self, topic: str) -> None:
        fqn = self.fqn(topic)

        def on_sample(sample: zenoh.Sample) -> None:
            self.emit("raw", data=sample.payload.to_bytes().hex())

        self._keep.append(self.node.session.declare_subscriber(fqn, on_sample))

    def cmd_ms_token(self, topic: str, type: str) -> None:
        fqn = self.fqn(topic)
        key = message_token(fqn, "raw-process", "raw-node", EntityKind.SUBSCRIBER, type)
        self._keep.append(self.node.session.liveliness().declare_token(key))

    def cmd_raw_token(self, key: str) -> None:
        self._keep.append(self.node.session.liveliness().declare_token(key))

    def cmd_serve(self, service: str, req: str, rep: str) -> None:
        def handler(request: bytes) -> tuple[bool, bytes]:
            self.emit("request", service=service, data=request.hex())
            if request == b"fail":
                return False, b""
            if request == b"slow":
                time.sleep(SLOW_HANDLER)
            return True, b"re:" + request

        self._keep.append(self.node.advertise_service(service, req, rep, handler))

    def cmd_call(self, service: str, req: str, rep: str, data: str, timeout: float) -> None:
        def on_reply(ok: bool | None, payload: bytes) -> None:
            self.emit("reply", service=service, ok=ok, data=payload.hex())

        self.node.request_async(service, bytes.fromhex(data), req, rep, timeout, on_reply)

    def cmd_wait_publishers(self, topic: str, present: bool) -> dict[str, Any]:
        return {"ok": self.wait_until(lambda: bool(self.node.topic_info(topic)) == present)}

    def cmd_wait_services(self, service: str, present: bool) -> dict[str, Any]:
        return {"ok": self.wait_until(lambda: bool(self.node.service_info(service)) == present)}

    def cmd_stats(self) -> dict[str, Any]:
        return self.node.stats.as_dict()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("role", choices=["node", "router"])
    parser.add_argument("--mode", default="peer")
    parser.add_argument("--listen", action="append", default=[])
    parser.add_argument("--connect", action="append", default=[])
    args = parser.parse_args()
    if args.role == "router":
        with zenoh.open(endpoints_config("router", args.listen)):
            sys.stdout.write(json.dumps({"event": "ready"}) + "\n")
            sys.stdout.flush()
            sys.stdin.read()
        return
    node = ZenohGzNode(config=endpoints_config(args.mode, args.listen, args.connect))
    peer = PeerNode(node)
    peer.emit("ready", process_uuid=node.process_uuid)
    for line in sys.stdin:
        command = json.loads(line)
        name = command["cmd"]
        peer.emit("done", cmd=name, **peer.run(command))
    node.close()


if __name__ == "__main__":
    main()
