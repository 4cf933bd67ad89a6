"""Shared pieces of the end-to-end behaviour tests: a bridge process, a ROS side, a Gazebo side.

* :func:`start_bridge` runs the real ``parameter_bridge`` console script (through
  :func:`testing.gzpeer.start_process`, so it inherits the loopback environment of
  ``tests/conftest.py`` and is killed with the other started processes).
* :class:`RosSide` is an rclpy node in a context of its own, spun by a background thread; every
  call that touches the node goes through :meth:`RosSide.run`, which holds the lock the spin
  loop holds, so entities are never created or destroyed under a running ``spin_once``.
* The Gazebo side is our own ``ZmqGzNode`` (``create_gz_node()``), whose publishers tell through
  ``has_connections()`` whether the bridge subscribed, and whose discovery lists what the
  bridge advertised.

Processes started by a test are stopped by the ``started`` fixture; module-scoped bridges stop
at the end of their module (never through ``stop_processes``, which would stop every module's).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.utilities import try_shutdown

from ros_gz_bridge_py.transport import GzNode, create_gz_node
from testing.e2e_harness import PARAMETER_BRIDGE
from testing.gzpeer import Inbox, PeerProcess, start_process, wait_for_line, wait_until

STRING = "ignition.msgs.StringMsg"
#: Upper bound of every wait for something that should happen (discovery, delivery).
WAIT = 10.0
_T = TypeVar("_T")


def bridge_command(*args: str, ros_args: Sequence[str] = ()) -> list[str]:
    """The ``parameter_bridge`` command line for positional ``args`` and ``--ros-args``."""
    command = [str(PARAMETER_BRIDGE), *args]
    if ros_args:
        command += ["--ros-args", *ros_args]
    return command


def start_bridge(*args: str, ros_args: Sequence[str] = (), creating: int = 0) -> PeerProcess:
    """Start ``parameter_bridge`` and wait for ``creating`` ``Creating ...`` log lines."""
    bridge = start_process(bridge_command(*args, ros_args=ros_args))
    for _ in range(creating):
        wait_for_line(bridge, r"\]: Creating ", timeout=30)
    return bridge


def relative(name: str) -> str:
    """``/stem_pid_hex`` -> ``stem_pid_hex`` (a unique relative name)."""
    return name.lstrip("/")


class RosSide:
    """A test node of its own context, spun in a background thread."""

    def __init__(self, name: str) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node: Any = rclpy.create_node(name, context=self.context)
        self._executor = SingleThreadedExecutor(context=self.context)
        self._executor.add_node(self.node)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="ros-side", daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set():
            with self._lock:
                self._executor.spin_once(timeout_sec=0.02)
            time.sleep(0.001)

    def run(self, action: Callable[[], _T]) -> _T:
        """Run ``action`` (something touching the node) between two spins."""
        with self._lock:
            return action()

    def subscribe(self, msg_type: Any, topic: str, qos: QoSProfile | int = 10) -> tuple[Inbox, Any]:
        """A subscription collecting into an :class:`Inbox` (items are ``(message, None)``)."""
        inbox = Inbox()
        subscription = self.run(
            lambda: self.node.create_subscription(msg_type, topic, lambda m: inbox(m, None), qos)
        )
        return inbox, subscription

    def destroy(self, entity: Any) -> None:
        """Destroy a subscription or publisher of the node."""
        destroyers = (
            self.node.destroy_subscription,
            self.node.destroy_publisher,
            self.node.destroy_client,
        )
        self.run(lambda: any(destroy(entity) for destroy in destroyers))

    def count_subscribers(self, topic: str) -> int:
        return int(self.run(lambda: self.node.count_subscribers(topic)))

    def count_publishers(self, topic: str) -> int:
        return int(self.run(lambda: self.node.count_publishers(topic)))

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self._executor.shutdown(timeout_sec=1)
        self.node.destroy_node()
        try_shutdown(context=self.context)


def publish_until(
    publish: Callable[[int], object], done: Callable[[], bool], what: str, period: float = 0.1
) -> int:
    """Call ``publish(i)`` for i = 0, 1, ... every ``period`` s until ``done()``; returns i.

    The first messages after discovery are often lost (volatile QoS, ZeroMQ connecting), so
    delivery checks publish repeatedly, bounded by :data:`WAIT`.
    """
    deadline = time.monotonic() + WAIT
    index = 0
    while not done():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {WAIT} s publishing until {what}")
        publish(index)
        index += 1
        time.sleep(period)
    return index


def holds_for(condition: Callable[[], bool], seconds: float) -> bool:
    """Whether ``condition()`` stays true during ``seconds`` (polled every 20 ms)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if not condition():
            return False
        time.sleep(0.02)
    return condition()


def gz_advertised(gz_node: GzNode, topic: str, msg_type: str = STRING) -> bool:
    """Whether some process advertises ``topic`` with ``msg_type`` on the Gazebo side."""
    return any(info.msg_type == msg_type for info in gz_node.topic_info(topic))


def wait_gz_advertised(gz_node: GzNode, topic: str, msg_type: str = STRING) -> None:
    wait_until(lambda: gz_advertised(gz_node, topic, msg_type), WAIT, f"{topic} advertised")


@pytest.fixture
def started() -> Iterator[list[PeerProcess]]:
    """Processes a test starts itself: append them; they are stopped at test end."""
    processes: list[PeerProcess] = []
    yield processes
    for process in processes:
        process.stop()


@pytest.fixture
def probe(request: pytest.FixtureRequest) -> Iterator[RosSide]:
    """The ROS side of one test, a node named after its module (``test_x`` -> ``x_probe``)."""
    module = request.module.__name__.rsplit(".", 1)[-1].removeprefix("test_")
    side = RosSide(f"{module}_probe")
    yield side
    side.close()


@pytest.fixture(scope="module")
def ros_side() -> Iterator[RosSide]:
    side = RosSide(f"behaviour_test_{threading.get_ident() % 100000}")
    yield side
    side.close()


@pytest.fixture(scope="module")
def gz_node() -> Iterator[GzNode]:
    with create_gz_node() as node:
        yield node
