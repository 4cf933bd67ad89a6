"""A Gazebo-side service provider over Zenoh: ``python e2e_zenoh_extras.py SERVICE SECONDS``.

Our ``ZenohGzNode`` (created as gz-transport 15 creates one, from ``GZ_TRANSPORT_IMPLEMENTATION``
and ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE``) offers SERVICE with ``gz.msgs.WorldControl``
requests and ``gz.msgs.Boolean`` replies, answering ``data: true``. Output: ``NODE <class>``,
``READY``, then ``REQUEST <one-line text of the request>`` per request. Runs until SIGTERM or
SECONDS pass.
"""

from __future__ import annotations

import sys
import time

from google.protobuf import text_format

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import create_gz_node

REQUEST_TYPE = "gz.msgs.WorldControl"
REPLY_TYPE = "gz.msgs.Boolean"


def emit(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def main() -> int:
    service, seconds = sys.argv[1], float(sys.argv[2])
    with StopSignal() as stop:
        request_class = message_class(REQUEST_TYPE)
        reply = message_class(REPLY_TYPE)(data=True).SerializeToString()

        def handle(payload: bytes) -> tuple[bool, bytes]:
            request = request_class.FromString(payload)
            emit(f"REQUEST {text_format.MessageToString(request, as_one_line=True)}")
            return True, reply

        with create_gz_node() as node:
            emit(f"NODE {type(node).__name__}")
            node.advertise_service(service, REQUEST_TYPE, REPLY_TYPE, handle)
            emit("READY")
            end = time.monotonic() + seconds
            while not stop.requested and time.monotonic() < end:
                time.sleep(0.05)
        return 0


if __name__ == "__main__":
    sys.exit(main())
