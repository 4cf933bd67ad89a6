"""Wire-level conversions: bytes made by real Ignition Transport 11 programs, converted by us.

Gazebo to ROS: for one representative pair of each gz package family, a real publisher (the C++
peer's ``pub`` mode, and for two cases also the Debian CLI one-shot ``ign-transport-topic -p``)
sends a message built from a text protobuf with distinctive values. Our ZmqGzNode subscribes raw
with the exact Fortress type string ``ignition.msgs.X``; the bytes are decoded with
``message_class("ignition.msgs.X")``, converted with the registry's pair, and the ROS fields are
checked against ``docs/conversions.md`` and ``docs/conversions-per-package.md`` (their section
numbers are in the checks). The peer
prints the SHA-256 of what it serialized, so each case also proves that the bytes we converted
are exactly the C++ ones.

Of the pairs added for issue 16, LogicalCameraImage and LogPlaybackStatistics are checked here
both ways. AirSpeed, DVLVelocityTracking (Harmonic+) and NavSatWithCovariance (Jetty) are not:
ign-msgs 8 has no such types, so the Fortress peer can neither build nor decode them.

The other direction is in ``test_conversion_wire_ros_to_gz.py``; the cases in
``wire_cases_common_msgs.py`` and ``wire_cases_other_msgs.py``.

All deliveries happen once per module, in a module-scoped fixture that runs a few publishers at a
time and stops every process it started before the first test runs; each test then checks one
delivery.
"""

from __future__ import annotations

import hashlib
import re
import time
from dataclasses import dataclass, field
from typing import Any

import pytest

from ros_gz_bridge_py.converters import default_registry
from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import (
    IGN_TOPIC,
    Inbox,
    PeerProcess,
    peer_binary,
    start_peer,
    start_process,
    stop_processes,
    unique_name,
)
from tests.interop import wire_cases_common_msgs, wire_cases_other_msgs
from tests.interop.wire_case import Case
from tests.interop.wire_runs import DELIVERY_TIMEOUT, PARALLEL, run_limited

pytestmark = pytest.mark.peer

#: The CLI publishes once, 800 ms after advertising, and exits as it does: about one message
#: in four never reaches the wire (docs/protocol-zmq-data.md §2.8.7; before our subscribers stayed
#: connected a moment after a publisher's goodbye, two in three were lost): up to 6 one-shots
#: per case, each a fresh publisher process.
CLI_ATTEMPTS = 6
#: After a one-shot CLI exits, how long its message may still be on its way to us.
CLI_GRACE = 1.0
PEER_ATTEMPTS = 2

CASES = (*wire_cases_common_msgs.CASES, *wire_cases_other_msgs.CASES)
DELIVERIES = [(case, "peer") for case in CASES] + [(c, "cli") for c in CASES if c.cli]


@dataclass
class Delivery:
    """What one publisher delivered to our raw subscriber."""

    payload: bytes | None = None
    msg_type: str = ""
    #: The peer's ``PAYLOAD sha256=.. len=..`` digest of what it serialized ("" for the CLI).
    peer_digest: str = ""
    log: list[str] = field(default_factory=list)


class _Publishing:
    """One (case, source) delivery in flight: our subscription plus the real publisher."""

    def __init__(self, node: Any, case: Case, source: str) -> None:
        self.case = case
        self.source = source
        self.topic = unique_name(f"wire_{case.name}_{source}")
        self.inbox = Inbox()
        self.subscription = node.subscribe(self.topic, self.inbox, msg_type=case.gz_type)
        self.result = Delivery()
        self.attempts = 0
        self.proc: PeerProcess | None = None
        self.started = 0.0
        self.exited = 0.0

    def start(self) -> None:
        self.attempts += 1
        self.started = time.monotonic()
        self.exited = 0.0
        if self.source == "peer":
            args = ("pub", self.topic, self.case.gz_type, "20", "0", self.case.text)
            self.proc = start_peer(*args, "--wait", "10", "--linger", "0")
        else:
            command = [str(IGN_TOPIC), "-t", self.topic, "-m", self.case.gz_type]
            self.proc = start_process([*command, "-p", self.case.text])

    def _stop(self) -> None:
        assert self.proc is not None
        self.proc.stop()
        self.result.log.append(f"attempt {self.attempts}: {self.proc.args!r}\n{self.proc.output()}")

    def step(self) -> bool:
        """Advance; True once finished (delivered, or out of attempts)."""
        assert self.proc is not None
        items = self.inbox.items()
        now = time.monotonic()
        if items:
            payload, info = items[0]
            self._stop()
            self.result.payload = bytes(payload)
            self.result.msg_type = info.msg_type
            digest = re.search(r"^PAYLOAD (sha256=\w+ len=\d+)$", self.proc.output(), re.M)
            self.result.peer_digest = digest.group(1) if digest else ""
            self.subscription.close()
            return True
        if self.proc.poll() is not None and not self.exited:
            self.exited = now
        grace_over = self.exited and now - self.exited > CLI_GRACE
        if not grace_over and now - self.started < DELIVERY_TIMEOUT:
            return False
        self._stop()
        if self.attempts < (PEER_ATTEMPTS if self.source == "peer" else CLI_ATTEMPTS):
            self.start()
            return False
        self.subscription.close()
        return True


@pytest.fixture(scope="module")
def deliveries(module_gz_node: Any) -> dict[tuple[str, str], Delivery]:
    """Every (case name, source) delivery, made once; all processes stopped before return."""
    peer_binary()
    jobs = [_Publishing(module_gz_node, case, source) for case, source in DELIVERIES]
    try:
        run_limited(jobs, PARALLEL)
    finally:
        stop_processes()
    return {(job.case.name, job.source): job.result for job in jobs}


@pytest.mark.parametrize(
    ("case", "source"),
    DELIVERIES,
    ids=[f"{case.name}-{source}" for case, source in DELIVERIES],
)
def test_real_publisher_bytes_convert_to_the_expected_ros_message(
    case: Case, source: str, deliveries: dict[tuple[str, str], Delivery]
) -> None:
    delivery = deliveries[case.name, source]
    assert delivery.payload is not None, "nothing arrived:\n" + "\n".join(delivery.log)
    assert delivery.msg_type == case.gz_type
    if source == "peer":
        sha = hashlib.sha256(delivery.payload).hexdigest()
        assert delivery.peer_digest == f"sha256={sha} len={len(delivery.payload)}"

    gz_msg = message_class(case.gz_type).FromString(delivery.payload)
    pair = default_registry().get(case.ros_type, case.gz_type)
    ros = pair.to_ros(gz_msg)

    assert isinstance(ros, pair.ros_class)
    case.check(ros)
