"""A ROS -> Gazebo channel's pump for the native tests (test_ros_pump_loop.py,
failed_copy_ros_side.py): a ``std_msgs/String`` publisher and raw subscription of the test's own
context feed it, a SUB socket connected to its PUB socket reads the data frames.
"""

from __future__ import annotations

import ctypes
import time
from collections.abc import Callable
from typing import Any

import pytest
import zmq

from ros_gz_bridge_py.transport.budget import TURN_MESSAGES, TURN_SLICE

TYPE = b"ignition.msgs.StringMsg"
TOPIC = b"@/partition@/ros_loop_test"
SENDER = b"tcp://127.0.0.1:1"
#: Each publish waits for delivery (DDS, then ZeroMQ) at most this long.
WAIT = 10.0
#: The budget of the loops the tests make (transport/budget.py); a slice of a second where a
#: test counts the messages of one turn, which a busy machine must not cut short.
BUDGET, LONG_SLICE = (TURN_MESSAGES, round(TURN_SLICE * 1e9)), (TURN_MESSAGES, 10**9)
SEND = ctypes.CFUNCTYPE(
    ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, use_errno=True
)


def functions() -> dict[str, int]:
    """The functions a RosPump calls, by name (skips where rcl cannot be called from C)."""
    from ros_gz_bridge_py.native.abi import ros_functions  # noqa: PLC0415

    found = ros_functions()
    if found is None:
        pytest.skip("rcl cannot be called from C here")
    return found


def libzmq() -> Any:
    """The libzmq pyzmq loaded."""
    from ros_gz_bridge_py.native.abi import libzmq_path  # noqa: PLC0415

    path = libzmq_path()
    assert path is not None  # pyzmq is imported
    return ctypes.CDLL(path)


class Channel:
    """One channel: a publisher and a raw subscription of ``ros_context``, a PUB socket and a
    SUB socket reading it, and the C pump between them."""

    def __init__(self, native: Any, context: Any, name: str, send: int | None = None) -> None:
        import rclpy  # noqa: PLC0415
        from std_msgs.msg import String  # noqa: PLC0415

        from ros_gz_bridge_py.converters.registry import default_registry  # noqa: PLC0415
        from ros_gz_bridge_py.native.channel import encoder_of  # noqa: PLC0415

        self.String = String
        self.node = rclpy.create_node(name, context=context)
        self.publisher = self.node.create_publisher(String, f"/{name}", 100)
        self.subscription = self.node.create_subscription(
            String, f"/{name}", lambda _m: None, 100, raw=True
        )
        self.zmq = zmq.Context()
        self.pub = self.zmq.socket(zmq.PUB)
        self.pub.setsockopt(zmq.LINGER, 0)
        self.pub.bind("tcp://127.0.0.1:*")
        self.sub = self.zmq.socket(zmq.SUB)
        self.sub.setsockopt(zmq.LINGER, 0)
        self.sub.setsockopt(zmq.SUBSCRIBE, b"")
        self.sub.connect(self.pub.getsockopt_string(zmq.LAST_ENDPOINT))
        encoder = encoder_of(default_registry().get("std_msgs/msg/String", TYPE.decode()))
        assert encoder is not None
        addresses = functions()
        if send is not None:
            addresses = {**addresses, "zmq_send": send}
        self.pump = native.RosPump(
            addresses,
            self.subscription.handle.pointer,
            self.pub.underlying,
            [(TYPE, TOPIC, SENDER, encoder)],
            0.0,
        )
        self.pump.set_active({TYPE})
        self._loops: list[Any] = []
        self._wait_connected()

    def _wait_connected(self) -> None:
        """A PUB socket drops what it sends before the SUB socket's connection is made."""
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            self.pub.send(b"probe")
            if self.sub.poll(50):
                self.sub.recv()
                return
        pytest.fail("the SUB socket did not connect")

    def publish(self, text: str) -> None:
        self.publisher.publish(self.String(data=text))

    def messages(self, count: int) -> list[list[bytes]]:
        """The next ``count`` data messages the SUB socket reads (the probes skipped), then
        any that come within 0.2 s more."""
        out: list[list[bytes]] = []
        deadline = time.monotonic() + WAIT
        while len(out) < count and time.monotonic() < deadline:
            if self.sub.poll(50):
                out.append(self.sub.recv_multipart())
        while self.sub.poll(200):
            out.append(self.sub.recv_multipart())
        return [m for m in out if m != [b"probe"]]

    def remove_from(self, loop: Any) -> None:
        """Taken off ``loop`` when closed (rcl's callback must go before the subscription)."""
        self._loops.append(loop)

    def close(self) -> None:
        for loop in self._loops:
            loop.remove(self.pump)
        self.sub.close()
        self.pub.close()
        self.zmq.term()
        self.node.destroy_node()


def run_until(loop: Any, done: Callable[[list[Any]], bool], what: str) -> list[Any]:
    """Runs the loop (100 ms at a time) until ``done(everything reported so far)``, a list of
    (member, events)."""
    reported: list[Any] = []
    deadline = time.monotonic() + WAIT
    while not done(reported):
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        reported += loop.run(100, [])[1]
    return reported
