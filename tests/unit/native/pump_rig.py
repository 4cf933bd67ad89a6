"""A Gazebo -> ROS pump on a loop of its own, in process, for the native tests (test_pump_loop.py,
failed_copy_side.py): real ZeroMQ sockets (a PUB that stands for a Gazebo publisher, the SUB
the loop reads) and a real rclpy publisher the pump publishes on. What a socket owner does in
Python (learning the routes of what the loop hands back) the rig does itself.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import zmq

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.abi import zmq_functions
from ros_gz_bridge_py.native.channel import program_of
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES, TURN_SLICE

TOPIC = b"@/test_partition@/pumped"
TYPE = b"ignition.msgs.StringMsg"
LEGIT = b"legit-sender"
PAYLOAD = message_class("gz.msgs.StringMsg")(data="pumped").SerializeToString()
#: The budget of the loops the tests make (transport/budget.py).
BUDGET = (TURN_MESSAGES, round(TURN_SLICE * 1e9))


class Rig:
    """A pump on a loop, reading a SUB socket that a PUB of the test sends to."""

    def __init__(
        self,
        native: Any,
        publisher: Any,
        *,
        capacity: int,
        max_bytes: int,
        judge: Callable[[list[Any]], None] | None = None,
    ) -> None:
        functions = zmq_functions()
        program = program_of(default_registry().get("std_msgs/msg/String", "gz.msgs.StringMsg"))
        assert functions is not None
        assert program is not None
        self.pump = native.Pump(
            TOPIC, functions, publisher.handle.pointer, {TYPE: program}, capacity, 0.0, max_bytes
        )
        self.loop = native.Loop(*BUDGET)
        self.context = zmq.Context()
        self.pub = self.context.socket(zmq.PUB)
        self.pub.setsockopt(zmq.SNDHWM, 0)  # the test's bursts are not to be dropped by ZeroMQ
        port = self.pub.bind_to_random_port("tcp://127.0.0.1")
        self.sub = self.context.socket(zmq.SUB)
        self.sub.setsockopt(zmq.RCVHWM, 0)
        self.sub.setsockopt(zmq.SUBSCRIBE, TOPIC)
        self.sub.connect(f"tcp://127.0.0.1:{port}")
        self.pump.read_from(self.sub.underlying, 0)
        self.loop.add(self.pump)
        #: What a socket owner does with the frames handed back: by default, learn the route.
        self.judge = judge or (lambda frames: self.pump.learn(frames[1], frames[3], True))
        self.handed_senders: list[bytes] = []
        self.grown: list[int] = []  # what each hand-over said of payloads above the watched size

    def send(self, sender: bytes, payload: bytes) -> None:
        self.pub.send_multipart([TOPIC, sender, payload, TYPE])

    def connected(self) -> None:
        """Sends until a message arrives (a SUB connects asynchronously); learns its route."""
        deadline = time.monotonic() + 10
        while not self.handed_senders and time.monotonic() < deadline:
            self.send(LEGIT, b"")
            self.turn(50)
        assert self.handed_senders, "the SUB socket never connected"

    def turn(self, timeout_ms: int = 20) -> bool:
        """One run of the loop, then what a socket owner does: judge every message handed back
        as unrouted. Whether the loop reported the pump."""
        _woken, reported = self.loop.run(timeout_ms, [])
        for _pump, _events in reported:
            handover = self.pump.take_handed()
            for frames in handover.unrouted:
                self.handed_senders.append(frames[1])
                self.judge(frames)
            if handover.grown:
                self.grown.append(handover.grown)
        return bool(reported)

    def settle(self) -> None:
        """Runs until nothing more arrives for a while."""
        before = -1
        while self.pump.counts() != before:
            before = self.pump.counts()
            self.turn(100)

    def close(self) -> None:
        self.loop.remove(self.pump)
        self.pub.close(linger=0)
        self.sub.close(linger=0)
        self.context.term()
