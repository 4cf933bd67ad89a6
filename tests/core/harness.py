"""In-process pieces of the core tests: a ROS world, bridges on a memory network, waiting.

* :class:`RosWorld` is one rclpy context with a test node, spun by one executor thread that
  also spins the node of every bridge (its heartbeat and explain timers, its ROS->Gazebo
  callbacks). Whatever creates or destroys entities on a spun node goes through
  :meth:`RosWorld.run`, which holds the lock the spin loop holds (as ``RosSide`` of
  ``testing/behaviour_harness.py`` does), so nothing changes under a running ``spin_once``.
* :class:`Rig` is one :class:`~ros_gz_bridge_py.core.bridge.Bridge` on a ``MemoryGzNode`` of
  a private ``MemoryNetwork``; :meth:`Rig.gazebo` adds nodes on that network that play Gazebo
  processes (``native=Spelling.IGNITION`` for a Fortress one).

Waits poll a condition with a bound and fail the test naming what did not happen; no test
asserts on how long anything took.
"""

from __future__ import annotations

import dataclasses
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any, TypeVar

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.utilities import try_shutdown

from ros_gz_bridge_py.config import BridgeSpec
from ros_gz_bridge_py.converters.registry import Registry
from ros_gz_bridge_py.core.bridge import Bridge, BridgeHandle
from ros_gz_bridge_py.core.channel import Channel
from ros_gz_bridge_py.core.gz_to_ros import GzToRosChannel
from ros_gz_bridge_py.core.options import BridgeOptions
from ros_gz_bridge_py.core.ros_to_gz import RosToGzChannel
from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode

#: History depth of the test node's endpoints: deeper than any burst a test sends, so the
#: test's reader keeps every message until its executor takes it.
TEST_DEPTH = 100
#: Upper bound of every wait for something that should happen (discovery, delivery).
WAIT = 10.0
#: A heartbeat period no test outlives: lazy re-checks happen only when a test calls them.
MANUAL_HEARTBEAT = 3600.0
#: The options of a test bridge unless the test changes them: no timers doing work behind
#: the test's back (lazy checks and explanations are called by the tests that want them).
TEST_OPTIONS = BridgeOptions(heartbeat=MANUAL_HEARTBEAT, explain=False)

_T = TypeVar("_T")


def unique(stem: str) -> str:
    """A topic or service name no other test of this run uses."""
    return f"/core_{stem}_{uuid.uuid4().hex[:8]}"


def wait_until(condition: Callable[[], bool], what: str, timeout: float = WAIT) -> None:
    """Poll ``condition`` until true; fail the test naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.005)


def publish_until(publish: Callable[[int], object], done: Callable[[], bool], what: str) -> int:
    """Call ``publish(i)`` for i = 0, 1, ... until ``done()``; returns how many were sent.

    A reliable ROS endpoint gets every message once it has matched its peer, which takes
    DDS a moment even in one process; until then messages are published until one arrives.
    """
    deadline = time.monotonic() + WAIT
    sent = 0
    while not done():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {WAIT} s publishing until {what}")
        publish(sent)
        sent += 1
        time.sleep(0.01)
    return sent


class Inbox:
    """What a callback received, in order; ``inbox(message)`` or ``inbox(message, info)``."""

    def __init__(self) -> None:
        self._changed = threading.Condition()
        self._items: list[tuple[Any, Any]] = []

    def __call__(self, message: Any, info: Any = None) -> None:
        with self._changed:
            self._items.append((message, info))
            self._changed.notify_all()

    def messages(self) -> list[Any]:
        with self._changed:
            return [message for message, _ in self._items]

    def infos(self) -> list[Any]:
        with self._changed:
            return [info for _, info in self._items]

    def wait_for(self, condition: Callable[[list[Any]], bool], what: str) -> list[Any]:
        """Wait until ``condition(messages)`` holds; returns the messages then."""
        deadline = time.monotonic() + WAIT
        with self._changed:
            while not condition([message for message, _ in self._items]):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    pytest.fail(
                        f"timed out after {WAIT} s waiting for {what}; {len(self._items)} received"
                    )
                self._changed.wait(remaining)
            return [message for message, _ in self._items]


class RosWorld:
    """A context of its own with a test node, and the thread that spins it and the bridges."""

    def __init__(self, name: str) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node: Any = rclpy.create_node(name, context=self.context)
        self._executor = SingleThreadedExecutor(context=self.context)
        self._executor.add_node(self.node)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="core-ros-world", daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set():
            with self._lock:
                self._executor.spin_once(timeout_sec=0.01)
            time.sleep(0.0005)  # let run() take the lock between two spins

    def run(self, action: Callable[[], _T]) -> _T:
        """Run ``action`` (something touching a spun node) between two spins."""
        with self._lock:
            return action()

    def create_node(self, name: str, **kwargs: Any) -> Any:
        """A node of this context that nobody spins (the caller takes what it receives)."""
        return rclpy.create_node(name, context=self.context, **kwargs)

    def spin(self, node: Any) -> None:
        self.run(lambda: self._executor.add_node(node))

    def stop_spinning(self, node: Any) -> None:
        self.run(lambda: self._executor.remove_node(node))

    def subscribe(
        self, msg_type: Any, topic: str, qos: QoSProfile | int = TEST_DEPTH
    ) -> tuple[Inbox, Any]:
        inbox = Inbox()
        subscription = self.run(lambda: self.node.create_subscription(msg_type, topic, inbox, qos))
        return inbox, subscription

    def publisher(self, msg_type: Any, topic: str, qos: QoSProfile | int = TEST_DEPTH) -> Any:
        return self.run(lambda: self.node.create_publisher(msg_type, topic, qos))

    def destroy(self, entity: Any) -> None:
        """Destroy a subscription, publisher or client of the test node."""
        destroyers = (
            self.node.destroy_subscription,
            self.node.destroy_publisher,
            self.node.destroy_client,
        )
        self.run(lambda: any(destroy(entity) for destroy in destroyers))

    def subscribers(self, topic: str) -> list[Any]:
        """The subscriptions of ``topic`` the ROS graph shows (every node of the context)."""
        return list(self.run(lambda: self.node.get_subscriptions_info_by_topic(topic)))

    def publishers(self, topic: str) -> list[Any]:
        return list(self.run(lambda: self.node.get_publishers_info_by_topic(topic)))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self._executor.shutdown(timeout_sec=1)
        self.node.destroy_node()
        try_shutdown(context=self.context)


class Rig:
    """A bridge on a node of the world, on a memory network of its own, and Gazebo peers."""

    def __init__(
        self,
        world: RosWorld,
        options: BridgeOptions,
        *,
        registry: Registry | None = None,
        node_options: dict[str, Any] | None = None,
    ) -> None:
        self.world = world
        self.network = MemoryNetwork()
        self.node: Any = world.create_node(
            f"core_bridge_{uuid.uuid4().hex[:8]}", **(node_options or {})
        )
        self.gz = MemoryGzNode(network=self.network)
        self.bridge = world.run(
            lambda: Bridge(self.node, gz_node=self.gz, options=options, registry=registry)
        )
        world.spin(self.node)
        self._peers: list[MemoryGzNode] = []

    def add(self, spec: BridgeSpec) -> BridgeHandle:
        return self.world.run(lambda: self.bridge.add(spec))

    def remove(self, handle: BridgeHandle) -> None:
        self.world.run(lambda: self.bridge.remove(handle))

    def heartbeat(self) -> None:
        """One lazy re-check, as the bridge's timer makes it."""
        self.world.run(self.bridge.heartbeat)

    def gazebo(
        self, *, native: Spelling | None = None, partition: str | None = None
    ) -> MemoryGzNode:
        """A Gazebo process on the bridge's network (closed with the rig)."""
        peer = MemoryGzNode(partition=partition, network=self.network, native=native)
        self._peers.append(peer)
        return peer

    def close(self) -> None:
        self.world.stop_spinning(self.node)
        self.world.run(self.bridge.close)
        self.gz.close()
        for peer in self._peers:
            peer.close()
        self.node.destroy_node()


def gz_to_ros(handle: BridgeHandle) -> GzToRosChannel:
    """The Gazebo->ROS channel of ``handle``."""
    (channel,) = [c for c in handle.channels if isinstance(c, GzToRosChannel)]
    return channel


def ros_to_gz(handle: BridgeHandle) -> RosToGzChannel:
    """The ROS->Gazebo channel of ``handle``."""
    (channel,) = [c for c in handle.channels if isinstance(c, RosToGzChannel)]
    return channel


def settled(channel: Channel, received: int) -> None:
    """Wait until ``channel`` received ``received`` messages and finished each of them
    (published or counted as a conversion error; its own messages skipped are not received)."""
    stats = channel.stats

    def done() -> bool:
        return stats.received == received == stats.published + stats.conversion_errors

    wait_until(done, f"{channel.describe()} to handle {received} messages")


def options(**changes: Any) -> BridgeOptions:
    """:data:`TEST_OPTIONS` with ``changes``."""
    return dataclasses.replace(TEST_OPTIONS, **changes)
