"""The real ``parameter_bridge`` against a Gazebo subscriber that never reads (issue 29).

A bridge forwards camera images (sensor_msgs/Image of 3 MB, ROS -> Gazebo) to a rogue ZeroMQ
subscriber (``testing/rogue.py``) that subscribes through valid discovery and never reads, and
to a healthy Gazebo subscriber beside it. libzmq queues up to SNDHWM (1000) messages per
subscriber whatever their size: before images were sent from a socket whose queue is sized
for them, the bridge held every image it sent (+460 MB for 150 of them). Memory is the
bridge's own (VmRSS from /proc); what it published, from its ``/diagnostics``.
"""

from __future__ import annotations

import array
import itertools
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import Image

from ros_gz_bridge_py.transport import GzNode
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.settings import TransportSettings
from testing.behaviour_harness import WAIT, RosSide, gz_node, ros_side, start_bridge
from testing.gzpeer import Inbox, PeerProcess, unique_name, wait_until
from testing.procstat import PeakRss, usage
from testing.rogue import RogueSubscriber

__all__ = ["gz_node", "ros_side"]

pytestmark = [pytest.mark.ros]

MB = 1_000_000
GZ_IMAGE = "gz.msgs.Image"
SIDE = 1000
#: Images published at 50 Hz, 3 MB each: 450 MB, were they all kept.
COUNT = 150
#: Images the bridge must have sent to both subscribers: 150 MB, past the memory bound were
#: they all kept. A loaded machine's bridge takes fewer of the 150 (43, and 25 of 450, on 2
#: cores busy with other work: its subscription keeps the newest 10), so publishing goes on
#: until then, for at most PUBLISHING_LIMIT seconds.
NEEDED = 50
PUBLISHING_LIMIT = 60.0


class OutboundBridge:
    """A bridge process bridging one Image topic ROS -> Gazebo, and its /diagnostics."""

    def __init__(self, ros_side: RosSide, stem: str) -> None:
        self.topic = unique_name(stem)
        self.fqn = fully_qualified_name(TransportSettings.from_env().partition, "", self.topic)
        node_name = unique_name(f"{stem}_bridge").lstrip("/")
        self._status = (f"ros_gz_bridge: ROS->GZ {self.topic}", f"/{node_name}")
        self.diagnostics = Inbox()
        self._ros_side = ros_side
        self._entities = [
            ros_side.run(
                lambda: ros_side.node.create_subscription(
                    DiagnosticArray, "/diagnostics", lambda m: self.diagnostics(m, None), 10
                )
            )
        ]
        self.process: PeerProcess = start_bridge(
            f"{self.topic}@sensor_msgs/msg/Image]{GZ_IMAGE}",
            ros_args=["-r", f"__node:={node_name}", "-p", "status_period:=0.5"],
            creating=1,
        )
        self.publisher = ros_side.run(lambda: ros_side.node.create_publisher(Image, self.topic, 10))
        self._entities.append(self.publisher)

    def values(self) -> dict[str, str]:
        """The channel's key-values in the newest /diagnostics ({} before one)."""
        for message, _ in reversed(self.diagnostics.items()):
            for status in message.status:
                if (status.name, status.hardware_id) == self._status:
                    return {kv.key: kv.value for kv in status.values}
        return {}

    def published(self) -> int:
        return int(self.values().get("published", "0"))

    def close(self) -> None:
        for entity in self._entities:
            self._ros_side.destroy(entity)
        self.process.stop()


class Counter:
    """Counts the messages a subscription receives (keeping none of them)."""

    def __init__(self) -> None:
        self.count = 0
        self._lock = threading.Lock()

    def __call__(self, _payload: Any, _info: Any) -> None:
        with self._lock:
            self.count += 1


@pytest.fixture(params=[True, False], ids=["native", "python"])
def outbound(
    ros_side: RosSide, monkeypatch: pytest.MonkeyPatch, request: pytest.FixtureRequest
) -> Iterator[OutboundBridge]:
    """The bridge with the native data plane on (the default; images take the Python path
    anyway, docs/native.md) and off."""
    if not request.param:
        monkeypatch.setenv("ROS_GZ_BRIDGE_NATIVE", "off")
    bridge = OutboundBridge(ros_side, "never_reads")
    yield bridge
    bridge.close()


def test_a_subscriber_that_never_reads_costs_about_two_images(
    outbound: OutboundBridge, gz_node: GzNode
) -> None:
    """150 images of 3 MB (more until the bridge sent 50) to a subscriber that never reads, and
    to a healthy one: the bridge's resident memory grows by less than 100 MB (its send queue
    for the rogue holds 2 images, max_queued_bytes over the largest message the transport
    carries; the margin covers the ROS side's own buffers of a few images and the kernel's
    socket buffers), and the healthy subscriber receives most of what the bridge published."""
    healthy = Counter()
    subscription = gz_node.subscribe(outbound.topic, healthy, GZ_IMAGE, queue_size=10)
    rogue = RogueSubscriber(outbound.fqn, GZ_IMAGE)
    image = Image(height=SIDE, width=SIDE, encoding="rgb8", step=3 * SIDE)
    image.data = array.array("B", bytes(3 * SIDE * SIDE))
    try:
        wait_until(lambda: bool(rogue.connected), WAIT, "the rogue subscriber connects")

        def bridged_once() -> bool:
            outbound.publisher.publish(image)
            time.sleep(0.1)
            return outbound.published() > 0 and healthy.count > 0

        wait_until(bridged_once, WAIT, "the bridge sends to the subscribers")
        start = usage(outbound.process.pid).rss_bytes
        peak = PeakRss(outbound.process.pid)
        before, received_before = outbound.published(), healthy.count
        deadline = time.monotonic() + PUBLISHING_LIMIT
        for index in itertools.count(1):
            outbound.publisher.publish(image)
            time.sleep(0.02)
            if index >= COUNT and (
                outbound.published() - before >= NEEDED or time.monotonic() > deadline
            ):
                break
        time.sleep(1.0)  # the last of them bridged, and the next /diagnostics
        highest = peak.stop()
        sent = outbound.published() - before
        received = healthy.count - received_before
    finally:
        rogue.close()
        subscription.close()
    print(  # the figures for the report
        f"\nRSS start {start / MB:.1f} MB, peak {highest / MB:.1f} MB "
        f"(+{(highest - start) / MB:.1f} MB); {sent} images of 3 MB published, "
        f"{received} received by the healthy subscriber"
    )
    assert sent >= NEEDED, "the bridge kept publishing beside a subscriber that never reads"
    assert received >= sent // 2, "the healthy subscriber kept receiving"
    assert highest - start < 100 * MB
    assert outbound.values()["send_queue"] == "2"  # 64 MiB over 128 MiB, on /diagnostics
