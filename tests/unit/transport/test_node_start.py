"""A node's start that the caller can still stop (``transport/node_start.py``)."""

from __future__ import annotations

import threading

import pytest

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode
from ros_gz_bridge_py.transport.node_start import STOPPED, start_unless_stopped


def test_a_node_that_starts_is_returned() -> None:
    node = start_unless_stopped(
        lambda: MemoryGzNode(network=MemoryNetwork()), lambda: False, "memory"
    )
    assert isinstance(node, MemoryGzNode)
    assert not node.closed
    node.close()


def test_a_failed_start_raises_its_own_error() -> None:
    def fail() -> MemoryGzNode:
        msg = "cannot open the session"
        raise TransportError(msg)

    with pytest.raises(TransportError, match="cannot open the session"):
        start_unless_stopped(fail, lambda: False, "memory")


def test_a_stop_ends_the_wait_and_a_node_that_starts_later_is_closed() -> None:
    release = threading.Event()
    started: list[MemoryGzNode] = []

    def slow() -> MemoryGzNode:  # a Zenoh client waiting for its router
        release.wait(10.0)
        started.append(MemoryGzNode(network=MemoryNetwork()))
        return started[0]

    stop = threading.Event()
    threading.Timer(0.3, stop.set).start()
    with pytest.raises(TransportError, match=STOPPED):
        start_unless_stopped(slow, stop.is_set, "memory")
    release.set()
    for thread in threading.enumerate():
        if thread.name == "gz-node-start":
            thread.join(10.0)
    assert len(started) == 1
    assert started[0].closed
