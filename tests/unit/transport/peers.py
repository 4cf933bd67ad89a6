"""The discovery records of two made-up processes, for the discovery and spelling tests."""

from __future__ import annotations

from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.zmq.wire import MessagePublisher, PublisherRecord

ME = "11111111-1111-1111-1111-111111111111"
PEER = "22222222-2222-2222-2222-222222222222"
PEER_NODE = "33333333-3333-3333-3333-333333333333"
MY_NODE = "44444444-4444-4444-4444-444444444444"
TOPIC = "@/p@/x"


def record(
    process: str = PEER, address: str = "tcp://127.0.0.1:5000", scope: Scope = Scope.ALL
) -> PublisherRecord:
    node = PEER_NODE if process == PEER else MY_NODE
    return PublisherRecord(
        TOPIC, address, process, node, scope, MessagePublisher("gz.msgs.StringMsg")
    )
