"""Run by test_ros_pump_failed_copy.py with the failing-allocation shim preloaded: a ROS -> Gazebo
channel on its loop (ros_pump_rig's channel: a real rcl subscription, real ZeroMQ sockets)
takes two std_msgs/String messages the native encoder leaves to Python (data that is not
UTF-8): one of ``argv[3]`` CDR bytes, then one 4 bytes longer; allocations of ``argv[1]``
bytes fail while the loop handles them, but for the first ``argv[2]``. Prints, as JSON, the
sizes Python was handed, the pump's counts, the MemoryErrors raised and the shim's failures."""

from __future__ import annotations

import json
import struct
import sys
import time
import uuid
from typing import Any

from ros_gz_bridge_py.native import extension
from tests.unit.native.failing_alloc import while_failing
from tests.unit.native.ros_pump_rig import BUDGET, WAIT, Channel

COUNTS = ("received", "own_skipped", "rate_limited", "published", "take_errors",
          "send_failures", "lost")  # fmt: skip


def string_cdr(size: int, fill: bytes) -> bytes:
    """A little-endian CDR std_msgs/String of exactly ``size`` bytes: ``fill`` repeated."""
    length = size - 9  # the encapsulation, the string's length, its final NUL
    return b"\x00\x01\x00\x00" + struct.pack("<I", length + 1) + fill * length + b"\x00"


def outcome(loop: Any, channel: Channel, before: tuple[int, ...]) -> dict[str, Any]:
    """Runs the loop until both messages were taken and each handed to Python or counted as
    lost (``WAIT`` at most)."""
    refused: list[int] = []
    memory_errors = 0
    counts = dict.fromkeys(COUNTS, 0)
    deadline = time.monotonic() + WAIT
    while (counts["received"] < 2 or len(refused) + counts["lost"] < 2) and (
        time.monotonic() < deadline
    ):
        reported = loop.run(100, [])[1]
        for _pump, _events in reported:
            try:
                refused += [len(message) for message in channel.pump.take_handed()]
            except MemoryError:
                memory_errors += 1
        now = _counts(channel)
        counts = {name: b - a for name, a, b in zip(COUNTS, before, now, strict=True)}
    return {"refused": refused, "counts": counts, "memory_errors": memory_errors}


def _counts(channel: Channel) -> tuple[int, ...]:
    counts = channel.pump.counts()
    return tuple(getattr(counts, name) for name in COUNTS)


def main() -> None:
    import rclpy  # noqa: PLC0415 - only in this process
    from rclpy.context import Context  # noqa: PLC0415

    failing, spared, size = (int(argument) for argument in sys.argv[1:4])
    native = extension()
    assert native is not None
    context = Context()
    rclpy.init(context=context)
    channel = Channel(native, context, f"failed_copy_{uuid.uuid4().hex[:8]}")
    loop = native.Loop(*BUDGET)
    loop.add(channel.pump)
    channel.remove_from(loop)
    try:
        # sent natively; it grows the buffer the loop takes into past the sizes that follow
        channel.publisher.publish(string_cdr(size + 100, b"a"))
        deadline = time.monotonic() + WAIT
        while channel.pump.counts().published < 1 and time.monotonic() < deadline:
            loop.run(100, [])
        before = _counts(channel)
        assert before[3] == 1, before
        channel.publisher.publish(string_cdr(size, b"\xff"))
        channel.publisher.publish(string_cdr(size + 4, b"\xff"))
        report = while_failing(failing, lambda: outcome(loop, channel, before), spared)
        json.dump(report, sys.stdout)
    finally:
        channel.close()
        rclpy.try_shutdown(context=context)


if __name__ == "__main__":
    main()
