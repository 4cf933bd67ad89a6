"""A Zenoh router for the client-mode tests: ``python e2e_zenoh_router.py PORT SECONDS [HOST]``.

There is no ``zenohd`` here; a Python session in router mode routes the same way. It listens
on ``tcp/HOST:PORT`` only (HOST 127.0.0.1 unless given), without scouting, prints ``READY``
and runs until SIGTERM or ``SECONDS`` pass.
"""

from __future__ import annotations

import sys
import time

import zenoh

from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport.zenoh.config import endpoints_config


def main() -> int:
    port, seconds = int(sys.argv[1]), float(sys.argv[2])
    host = sys.argv[3] if len(sys.argv) > 3 else "127.0.0.1"
    with StopSignal() as stop:
        config = endpoints_config("router", listen=[f"tcp/{host}:{port}"])
        with zenoh.open(config):
            sys.stdout.write("READY\n")
            sys.stdout.flush()
            end = time.monotonic() + seconds
            while not stop.requested and time.monotonic() < end:
                time.sleep(0.05)
        return 0


if __name__ == "__main__":
    sys.exit(main())
