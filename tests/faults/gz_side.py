"""The simulator host's Gazebo side in the two-host Zenoh test (no Jetty binary exists here):
``python gz_side.py CLOCK_TOPIC CMD_TOPIC SECONDS`` with our ``ZenohGzNode`` made as gz makes
one (``GZ_TRANSPORT_IMPLEMENTATION``, ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE``).

Publishes ``gz.msgs.Clock`` at 20 Hz with an increasing ``sim`` time (1 ms steps, so every
message is unique) and prints ``TICK <sec> <nsec>``; subscribes to ``gz.msgs.Twist`` and prints
``MSG <linear.x>`` for each message. Ends after SECONDS or on SIGTERM.
"""

from __future__ import annotations

import sys
import time

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import MessageInfo, create_gz_node

Clock = message_class("gz.msgs.Clock")
Twist = message_class("gz.msgs.Twist")
PERIOD = 0.05


def emit(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def main() -> int:
    clock_topic, cmd_topic, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
    with StopSignal() as stop, create_gz_node() as node:

        def on_twist(message: object, _info: MessageInfo) -> None:
            emit(f"MSG {message.linear.x:g}")  # type: ignore[attr-defined]

        node.subscribe_typed(cmd_topic, Twist, on_twist)
        publisher = node.advertise(clock_topic, "gz.msgs.Clock")
        emit("READY")
        tick = 0
        end = time.monotonic() + seconds
        while not stop.requested and time.monotonic() < end:
            tick += 1
            clock = Clock()
            clock.sim.sec, clock.sim.nsec = divmod(tick * 1_000_000, 1_000_000_000)
            publisher.publish(clock)
            time.sleep(PERIOD)
    return 0


if __name__ == "__main__":
    sys.exit(main())
