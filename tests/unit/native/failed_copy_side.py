"""Run by test_pump_failed_copy.py with the failing-allocation shim preloaded: a pump on a loop
(pump_rig's rig: real ZeroMQ sockets, a real rclpy publisher) is sent payloads while the
allocations of ``argv[2]`` bytes fail; ``argv[3]`` is the payload size. ``argv[1]`` says what is
sent: ``copy``, a payload on each of the two ways a payload goes to Python, each followed by one
a byte longer; ``grow``, one String the program takes, whose output needs a larger buffer.
Prints, as JSON, what Python was handed, the pump's counts, the MemoryErrors raised and the
shim's failures."""

from __future__ import annotations

import json
import sys
import time
from typing import Any

from ros_gz_bridge_py.native import extension
from tests.unit.native.failing_alloc import while_failing
from tests.unit.native.pump_rig import LEGIT, TOPIC, TYPE, Rig

#: A sender the pump has no route for: its frames are handed to Python to judge.
UNKNOWN = b"unknown-sender"
COUNTS = ("received", "rate_limited", "published", "dropped", "skipped", "lost")
#: How each kind of hand-over is reported: the frames of an unrouted message, a refused payload.
UNROUTED, REFUSED = 0, 1


def string_msg(size: int, fill: bytes) -> bytes:
    """A StringMsg of exactly ``size`` bytes (data, field 2, with a 3-byte length) of
    ``fill`` repeated; with b"\\xff" (not UTF-8) the program finds it undecodable and hands it
    to Python, which says why."""
    length = size - 4
    assert 1 << 14 <= length < 1 << 21, "the length must take 3 bytes"
    varint = bytes([length & 0x7F | 0x80, length >> 7 & 0x7F | 0x80, length >> 14])
    return b"\x12" + varint + fill * length


def outcome(rig: Rig, sent: int) -> dict[str, Any]:
    """Runs the loop until each of the ``sent`` messages was published, handed to Python or
    counted as lost (10 s at most), keeping what was handed and the MemoryErrors of
    ``take_handed``."""
    before = _counts(rig)
    handed: list[dict[str, Any]] = []
    memory_errors = 0
    deadline = time.monotonic() + 10
    counts = dict.fromkeys(COUNTS, 0)
    while len(handed) + counts["lost"] + counts["published"] < sent and (
        time.monotonic() < deadline
    ):
        _woken, reported = rig.loop.run(100, [])
        for _pump, _events in reported:
            try:
                handover = rig.pump.take_handed()
            except MemoryError:
                memory_errors += 1
                continue
            for topic, sender, payload, msg_type in handover.unrouted:
                assert (topic, msg_type) == (TOPIC, TYPE)
                handed.append(_handed(UNROUTED, sender, payload, None))
            for refused in handover.refused:
                handed.append(_handed(REFUSED, refused.sender, refused.payload, refused.status))
        now = _counts(rig)
        counts = {name: b - a for name, a, b in zip(COUNTS, before, now, strict=True)}
    return {"handed": handed, "counts": counts, "memory_errors": memory_errors}


def _counts(rig: Rig) -> tuple[int, ...]:
    counts = rig.pump.counts()
    return tuple(getattr(counts, name) for name in COUNTS)


def _handed(kind: int, sender: bytes, payload: bytes, status: int | None) -> dict[str, Any]:
    return {"kind": kind, "sender": sender.decode(), "size": len(payload), "status": status}


def main() -> None:
    import rclpy  # noqa: PLC0415 - only in this process
    from rclpy.context import Context  # noqa: PLC0415
    from rclpy.node import Node  # noqa: PLC0415
    from std_msgs.msg import String  # noqa: PLC0415

    mode, failing, size = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    native = extension()
    assert native is not None
    context = Context()
    rclpy.init(context=context)
    node = Node("failed_copy_side", context=context)
    rig = Rig(native, node.create_publisher(String, "/failed_copy_side", 10), capacity=10,
              max_bytes=1 << 26)  # fmt: skip
    try:
        rig.connected()  # LEGIT's route is known from here on
        rig.settle()
        if mode == "copy":
            for payload_size in (size, size + 1):
                rig.send(UNKNOWN, string_msg(payload_size, b"u"))  # unrouted: frames to Python
                rig.send(LEGIT, string_msg(payload_size, b"\xff"))  # routed, refused: payload
        else:
            rig.send(LEGIT, string_msg(size, b"a"))
        sent = 4 if mode == "copy" else 1
        json.dump(while_failing(failing, lambda: outcome(rig, sent)), sys.stdout)
    finally:
        rig.close()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


if __name__ == "__main__":
    main()
