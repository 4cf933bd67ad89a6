"""The Gazebo side of the Zenoh end-to-end tests: our ``ZenohGzNode`` in a process of its own.

Usage: ``python e2e_zenoh_gazebo.py SPEC`` where SPEC is JSON::

    {"publish": [[topic, gz_type, text], ...], "echo": [[topic, gz_type], ...], "seconds": 60}

The node is created exactly as gz-transport 15 creates one: ``GZ_TRANSPORT_IMPLEMENTATION``
and the Zenoh configuration from ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE`` (set by the test).
Each publisher sends its message (protobuf text of the gz-msgs 10 type) at 5 Hz. Output, like
``ign_peer``: ``NODE <class>`` (the backend in use), ``READY``, then ``MSG <type> <one-line
text>`` per message echoed.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

from google.protobuf import text_format

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.stop_signal import StopSignal
from ros_gz_bridge_py.transport import MessageInfo, create_gz_node

_PUBLISH_PERIOD = 0.2


def emit(text: str) -> None:
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def main() -> int:
    spec = json.loads(sys.argv[1])
    with StopSignal() as stop, create_gz_node() as node:
        emit(f"NODE {type(node).__name__}")
        publishers = []
        for topic, gz_type, text in spec.get("publish", []):
            msg = text_format.Parse(text, message_class(gz_type)())
            publishers.append((node.advertise(topic, gz_type), msg))
        for topic, gz_type in spec.get("echo", []):

            def echo(msg: Any, info: MessageInfo) -> None:
                emit(f"MSG {info.msg_type} {text_format.MessageToString(msg, as_one_line=True)}")

            node.subscribe_typed(topic, message_class(gz_type), echo)
        emit("READY")
        end = time.monotonic() + float(spec.get("seconds", 60))
        while not stop.requested and time.monotonic() < end:
            for publisher, msg in publishers:
                publisher.publish(msg)
            time.sleep(_PUBLISH_PERIOD)
        return 0


if __name__ == "__main__":
    sys.exit(main())
