"""A native Gazebo -> ROS pump's publication windows (the loop guard, core/loop_guard.py): once
the topic is guarded, a sample with the pump's sequence number, written during the pump's call,
is the pump's only if its CDR is what the pump published. Real ZeroMQ sockets, a real rclpy
publisher the C loop publishes on and a real subscription that takes the sample and its info.
"""

from __future__ import annotations

import random
import time
from typing import Any

from rclpy.node import Node
from rclpy.serialization import serialize_message
from std_msgs.msg import String

from ros_gz_bridge_py.core.loop_guard import OwnPublications
from tests.unit.native.pump_rig import LEGIT, PAYLOAD, Rig


def _take(subscription: Any, data: bytes, timeout: float = 10.0) -> tuple[bytes, dict[str, Any]]:
    """The first CDR sample holding ``data``, with its message info."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        taken = subscription.handle.take_message(String, True)
        if taken is not None and data in taken[0]:
            return taken[0], taken[1]
        if taken is None:
            time.sleep(0.01)
    msg = f"no sample holding {data!r} within {timeout} s"
    raise AssertionError(msg)


def test_a_guarded_pump_knows_its_sample_by_content(
    native: Any, publisher: Any, ros_context: Any
) -> None:
    node = Node("pump_own_reader", context=ros_context)
    subscription = node.create_subscription(
        String, publisher.topic_name, lambda _msg: None, 100, raw=True
    )
    rig = Rig(native, publisher, capacity=100, max_bytes=1 << 20)
    try:
        deadline = time.monotonic() + 10
        while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.01)
        rig.connected()
        rig.settle()
        rig.pump.guard()
        rig.send(LEGIT, PAYLOAD)
        rig.settle()
        cdr, info = _take(subscription, b"pumped")
        sequence, stamp = info["publication_sequence_number"], info["source_timestamp"]
        assert rig.pump.is_own(sequence, stamp, cdr)
        assert rig.pump.is_own(sequence, stamp)  # no content to judge: number and time
        other = serialize_message(String(data="pumpee"))  # same length, another writer's
        assert len(other) == len(cdr)
        assert not rig.pump.is_own(sequence, stamp, other)
        assert not rig.pump.is_own(sequence, stamp - 10**9, cdr)
    finally:
        rig.close()
        node.destroy_node()


def test_a_python_publication_keeps_the_cdr_it_wrote(native: Any, publisher: Any) -> None:
    rig = Rig(native, publisher, capacity=100, max_bytes=1 << 20)
    try:
        ours, theirs = (serialize_message(String(data=text)) for text in ("ours", "them"))
        unknown = rig.pump.begin_publication()
        during_unknown = time.time_ns()
        rig.pump.end_publication(unknown, True)
        known = rig.pump.begin_publication()
        during_known = time.time_ns()
        rig.pump.end_publication(known, True, ours)
        assert rig.pump.is_own(unknown, during_unknown, theirs)  # nothing kept to tell
        assert rig.pump.is_own(known, during_known, ours)
        assert not rig.pump.is_own(known, during_known, theirs)
        assert not rig.pump.is_own(known, during_known, b"")
        # As a middleware may deliver it: padded to a multiple of 4, the count in the options
        # (XTypes, CycloneDDS), or zeros and nothing said (Fast DDS before 2.1).
        pad = -len(ours) % 4
        assert pad
        declared = ours[:3] + bytes([ours[3] | pad]) + ours[4:] + b"\xff" * pad
        assert rig.pump.is_own(known, during_known, declared)
        assert rig.pump.is_own(known, during_known, ours + bytes(pad))
    finally:
        rig.close()


class _Writer:
    """Publishes CDR bytes as they are, numbering and stamping each as rmw would."""

    def __init__(self) -> None:
        self.info: dict[str, int] = {}

    def publish(self, cdr: bytes) -> bytes:
        sequence = self.info.get("publication_sequence_number", 0) + 1
        self.info = {"publication_sequence_number": sequence, "source_timestamp": time.time_ns()}
        return cdr


def _variant(rng: random.Random, cdr: bytes) -> bytes:
    """What a subscription may receive: our sample as a middleware passed it on, or another
    writer's close to it."""
    pad = -len(cdr) % 4
    body = bytearray(cdr)
    where = rng.randrange(len(cdr))
    choices = [
        lambda: cdr,
        lambda: cdr[:3] + bytes([cdr[3] | pad]) + cdr[4:] + b"\xff" * pad,  # XTypes padding
        lambda: cdr + bytes(pad or 4),  # zeros, said nowhere
        lambda: cdr[:-1],
        lambda: cdr + bytes([rng.randrange(1, 256)]),
        lambda: (
            bytes(body[:where]) + bytes([body[where] ^ 1 << rng.randrange(8)]) + cdr[where + 1 :]
        ),
    ]
    return rng.choice(choices)()


def test_the_pump_and_the_python_guard_judge_content_alike(native: Any, publisher: Any) -> None:
    """The body rule is written twice, in Python (core/loop_guard.py ``_ends``) and in C
    (``rgb_cdr_digest``): over CDR of every size around the ends they keep (odd lengths,
    zeros at the end, declared padding, one bit flipped anywhere), both judge each received
    sample alike."""
    rng = random.Random(35)
    own = OwnPublications()
    own.guard()
    writer = _Writer()
    publish = own.wrap(writer)
    rig = Rig(native, publisher, capacity=100, max_bytes=1 << 20)
    verdicts = []
    try:
        for _ in range(600):
            size = rng.choice([4, 5, 8, 13, 255, 260, 512, 515, 516, 517, 600, 1500])
            body = bytes(rng.randrange(256) for _ in range(size - 4))
            if rng.random() < 0.3:
                body = body[: len(body) // 2] + bytes(len(body) - len(body) // 2)
            written = b"\x00\x01\x00\x00" + body
            received = _variant(rng, written)
            sequence = rig.pump.begin_publication()
            during = time.time_ns()
            rig.pump.end_publication(sequence, True, written)
            publish(written)
            native_verdict = rig.pump.is_own(sequence, during, received)
            assert own.is_own(writer.info, received) == native_verdict, (written, received)
            verdicts.append(native_verdict)
        assert 0.2 < sum(verdicts) / len(verdicts) < 0.8  # both kinds were judged
    finally:
        rig.close()
