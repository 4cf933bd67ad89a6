"""The Python path's reader keeps libzmq's queue in front of its own within the bytes bound:
its SUB socket's RCVHWM is lowered as payloads grow (``hwm.py``), on the reader's thread, the
socket's. The native pump does the same (tests/unit/native/test_pump_loop.py)."""

from __future__ import annotations

import threading
import time
from typing import Any

import zmq

from ros_gz_bridge_py.transport.api import MessageInfo, Rejection
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.hwm import hwm_for_bytes
from ros_gz_bridge_py.transport.zmq.reader import SubscriptionReader

FQN = "@/reader_hwm@/big"
TYPE = b"gz.msgs.StringMsg"
SENDER = "tcp://127.0.0.1:1"


def _rcvhwm(reader: SubscriptionReader) -> int:
    """The socket's RCVHWM, read on the reader's own thread."""
    seen: list[int] = []
    done = threading.Event()

    def read() -> None:
        seen.append(int(reader._sock.getsockopt(zmq.RCVHWM)))
        done.set()

    reader._post(read)
    assert done.wait(5)
    return seen[0]


def test_the_reader_lowers_its_rcvhwm_as_payloads_grow() -> None:
    settings = TransportSettings.from_env()
    context = zmq.Context()
    pub = context.socket(zmq.PUB)
    port = pub.bind_to_random_port("tcp://127.0.0.1")
    delivered: list[int] = []
    rejected: list[tuple[Rejection, str]] = []

    def deliver(payload: Any, _info: MessageInfo) -> None:
        delivered.append(len(payload))

    limit = 1_000_000
    reader = SubscriptionReader(
        context,
        fqn=FQN,
        partition="reader_hwm",
        accepts=lambda _sender, _type: True,
        takes=lambda _type: True,
        deliver=deliver,
        reject=lambda reason, detail: rejected.append((reason, detail)),
        size=1000,
        settings=settings,
        count=lambda *_args: None,
        max_bytes=limit,
    )
    try:
        reader.connect(f"tcp://127.0.0.1:{port}")
        deadline = time.monotonic() + 10
        while not delivered and time.monotonic() < deadline:  # a SUB connects asynchronously
            pub.send_multipart([FQN.encode(), SENDER.encode(), b"small", TYPE])
            time.sleep(0.05)
        assert delivered, "the reader never connected"
        assert _rcvhwm(reader) == settings.rcvhwm
        big = b"x" * 300_000
        pub.send_multipart([FQN.encode(), SENDER.encode(), big, TYPE])
        while len(big) not in delivered and time.monotonic() < deadline:
            time.sleep(0.02)
        assert _rcvhwm(reader) == hwm_for_bytes(len(big), limit, settings.rcvhwm) == 3
        assert not rejected
    finally:
        reader.close()
        pub.close(linger=0)
        context.term()
