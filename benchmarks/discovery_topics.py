"""The Gazebo side of the discovery benchmark: one process advertising N topics, then more.

Usage: ``python -m benchmarks.discovery_topics PREFIX N NEW START_FILE``. Advertises
``PREFIX/t<i>`` for i < N (``gz.msgs.StringMsg``, never published: discovery alone is
measured) and prints ``READY``; once ``START_FILE`` exists, advertises ``PREFIX/new<j>`` for
j < NEW, one every 0.5-1.0 s (at random, so that the bridge's scans, every 0.5 s, meet them
at every phase), each with a line ``ADVERTISED new<j> <CLOCK_MONOTONIC seconds>``
(comparable across processes on Linux); then waits to be stopped.
"""

from __future__ import annotations

import random
import sys
import time
from pathlib import Path

from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import create_gz_node

TYPE = "gz.msgs.StringMsg"


def main() -> int:
    prefix, count, new, start = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    with StopSignal() as stop, create_gz_node() as node:
        publishers = [node.advertise(f"{prefix}/t{i}", TYPE) for i in range(count)]
        print("READY", flush=True)
        while not start.exists() and not stop.requested:
            time.sleep(0.05)
        for j in range(new):
            if stop.requested:
                break
            publishers.append(node.advertise(f"{prefix}/new{j}", TYPE))
            print(f"ADVERTISED new{j} {time.monotonic():.6f}", flush=True)
            time.sleep(random.uniform(0.5, 1.0))  # timing, not secrets
        while not stop.requested:
            time.sleep(0.1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
