"""A child process for ``test_transport_disconnect.py``: receives one one-shot message
and disconnects from the publisher once it says goodbye, in a process of its own, because the
libzmq bug it is about aborts the process (``Assertion failed: !_more (src/fq.cpp)``).

    python -m tests.interop.one_shot_child MODE TOPIC

MODE ``plain`` does what a SUB socket owner naively does: it polls (libzmq takes the first
frame of the waiting message out of the pipe), sees the publisher's record go (UNADVERTISE,
BYE), disconnects, then reads. MODE ``ours`` lets our node (a queued and a direct
subscription) do it. Prints ``READY``, then ``RECEIVED n`` and ``DISCONNECTED n``, or
``NO DATA`` (exit 3) when the one-shot message did not arrive.
"""

from __future__ import annotations

import sys
import time

import zmq

from ros_gz_bridge_py.transport.zmq.node import ZmqGzNode

STRING = "ignition.msgs.StringMsg"
WAIT = 15.0


def plain(node: ZmqGzNode, topic: str) -> int:
    publishers = node.wait_for_publishers(topic, WAIT)
    if not publishers:
        print("NO DATA (no publisher)", flush=True)
        return 3
    context = zmq.Context()
    sub = context.socket(zmq.SUB)
    sub.setsockopt(zmq.SUBSCRIBE, node.fqn(topic).encode())
    sub.connect(publishers[0].address)
    deadline = time.monotonic() + WAIT
    while not sub.poll(100):  # the poll takes the message's first frame out of its pipe
        if time.monotonic() > deadline:
            print("NO DATA", flush=True)
            return 3
    while node.topic_info(topic) and time.monotonic() < deadline:
        time.sleep(0.05)  # the one-shot publisher says goodbye
    sub.disconnect(publishers[0].address)
    frames = 0
    try:
        while True:
            sub.recv(zmq.NOBLOCK)
            frames += 1
    except zmq.Again:
        pass
    print(f"RECEIVED {frames}", flush=True)
    return 0


def ours(node: ZmqGzNode, topic: str) -> int:
    received: list[bytes] = []
    node.subscribe(topic, lambda payload, _: received.append(payload), STRING, queue_size=10)
    node.subscribe(topic, lambda payload, _: received.append(payload), STRING)
    print("READY", flush=True)
    deadline = time.monotonic() + WAIT
    while len(received) < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    if not received:
        print("NO DATA", flush=True)
        return 3
    while node.stats.publishers_disconnected < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(0.5)  # anything still in flight is read
    print(f"RECEIVED {len(received)}", flush=True)
    print(f"DISCONNECTED {node.stats.publishers_disconnected}", flush=True)
    return 0


def main() -> int:
    mode, topic = sys.argv[1], sys.argv[2]
    with ZmqGzNode() as node:
        if mode == "ours":
            return ours(node, topic)
        node.subscribe(topic, lambda *_: None, STRING)  # NEW_CONNECTION: the one-shot sends
        node.topic_list()  # discovery initialised (2 s): listings answer at once from now on
        print("READY", flush=True)
        return plain(node, topic)


if __name__ == "__main__":
    sys.exit(main())
