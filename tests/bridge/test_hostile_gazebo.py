"""The real ``parameter_bridge`` against a hostile Gazebo side (issue 14, points 2-4).

Each test runs its own bridge process (``status_period:=0.5``) bridging one String topic
Gazebo -> ROS, reads its counters from ``/diagnostics`` with rclpy and its memory and CPU from
``/proc/<pid>``. The hostile peers (``testing/rogue.py``) are raw pyzmq sockets and raw discovery
datagrams on loopback, bounded in count and time; the real publisher is the C++ ign-transport
11 peer. Figures are printed (``-s`` shows them); asserts are the behaviour bounds of the
issue, with the margins explained where they are made.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from std_msgs.msg import String

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.settings import TransportSettings
from testing.behaviour_harness import STRING, WAIT, RosSide, ros_side, start_bridge
from testing.gzpeer import (
    Inbox,
    PeerProcess,
    gz_processes,
    ign_peer,
    start_peer,
    unique_name,
    wait_for_line,
    wait_until,
)
from testing.procstat import PeakRss, cpu_percent, usage
from testing.rogue import FakePeer, RoguePublisher, TrapListeners, closed_ports

__all__ = ["gz_processes", "ign_peer", "ros_side"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

GzString = message_class(STRING)
MB = 1_000_000


class BridgeUnderAttack:
    """A bridge process bridging ``topic`` Gazebo -> ROS, and its /diagnostics so far."""

    def __init__(self, ros_side: RosSide, stem: str, *parameters: str) -> None:
        self.topic = unique_name(stem)
        self.fqn = fully_qualified_name(TransportSettings.from_env().partition, "", self.topic)
        self.node_name = unique_name(f"{stem}_bridge").lstrip("/")
        self.status_name = f"ros_gz_bridge: GZ->ROS {self.topic}"
        self.diagnostics = Inbox()
        self._ros_side = ros_side
        self._subscription = ros_side.run(
            lambda: ros_side.node.create_subscription(
                DiagnosticArray, "/diagnostics", lambda m: self.diagnostics(m, None), 10
            )
        )
        self.process: PeerProcess = start_bridge(
            f"{self.topic}@std_msgs/msg/String[{STRING}",
            ros_args=[
                "-r",
                f"__node:={self.node_name}",
                "-p",
                "status_period:=0.5",
                *(arg for parameter in parameters for arg in ("-p", parameter)),
            ],
            creating=1,
        )
        self.ros_inbox, self._ros_subscription = ros_side.subscribe(String, self.topic)

    @property
    def pid(self) -> int:
        return self.process.pid

    def values(self) -> dict[str, str]:
        """The key-values of our channel in the newest /diagnostics array ({} before one)."""
        for array, _ in reversed(self.diagnostics.items()):
            for status in array.status:
                if status.name == self.status_name and status.hardware_id == f"/{self.node_name}":
                    return {kv.key: kv.value for kv in status.values}
        return {}

    def wait_for_value(self, key: str, expected: str) -> None:
        wait_until(lambda: self.values().get(key) == expected, WAIT, f"{key} = {expected}")

    def close(self) -> None:
        self._ros_side.destroy(self._subscription)
        self._ros_side.destroy(self._ros_subscription)
        self.process.stop()


@pytest.fixture
def bridge(ros_side: RosSide, request: pytest.FixtureRequest) -> Iterator[BridgeUnderAttack]:
    under_attack = BridgeUnderAttack(ros_side, request.node.name[5:25])
    yield under_attack
    under_attack.close()


def test_a_rogue_publishers_200_mb_frames_are_refused_counted_and_cost_no_memory(
    bridge: BridgeUnderAttack, ign_peer: Path, gz_processes: None
) -> None:
    """Issue 14, point 2: four 200 MB frames from a rogue publisher on the topic are refused
    before they are buffered (libzmq's ZMQ_MAXMSGSIZE, the default limit of 128 MiB) and
    counted; the bridge's resident memory stays within 100 MB of where it started (the
    campaign saw +1.6 GB without the limit; the margin covers the allocator and the counters,
    not one frame); the real C++ publisher on the same topic keeps reaching ROS throughout."""
    real = start_peer("pub", bridge.topic, STRING, "20", "0", 'data: "real"')
    wait_for_line(real, r"^READY$")
    bridge.ros_inbox.wait_for(lambda items: len(items) >= 5, WAIT, "the real publisher on ROS")
    start = usage(bridge.pid).rss_bytes
    peak = PeakRss(bridge.pid)
    rogue = RoguePublisher(bridge.fqn, STRING)
    frame = memoryview(bytes(200 * MB))
    try:
        for sent in range(1, 5):
            assert rogue.wait_subscribed(WAIT), f"the bridge connects for frame {sent}"
            rogue.send(frame)
            bridge.wait_for_value("errors: over the size limit", str(sent))
        during = len(bridge.ros_inbox.items())
        bridge.ros_inbox.wait_for(
            lambda items: len(items) >= during + 10, WAIT, "the real publisher after the frames"
        )
    finally:
        highest = peak.stop()
        rogue.close()
    end = usage(bridge.pid).rss_bytes
    values = bridge.values()
    print(  # the figures for the report
        f"\nRSS start {start / MB:.1f} MB, peak {highest / MB:.1f} MB, end {end / MB:.1f} MB; "
        f"errors {values['errors']}; last error: {values['last_error']}"
    )
    assert values["errors: over the size limit"] == "4"
    assert highest - start < 100 * MB
    assert "over the size limit" in bridge.process.output()


@pytest.mark.parametrize("native", [True, False], ids=["native", "python"])
def test_a_flood_past_max_queued_bytes_is_dropped_counted_and_told(
    ros_side: RosSide, monkeypatch: pytest.MonkeyPatch, native: bool
) -> None:
    """A bridge whose queues hold 2 MB (``max_queued_bytes``) takes messages of 1 MB from a
    rogue publisher, handed over far faster than it publishes them: the oldest are dropped,
    counted in the channel's drops on /diagnostics, and one warning names the topic and the
    rogue's address (before the parameter, the queue held 64 MiB: up to 64 of them). The
    first of them makes the bridge connect anew with a receive HWM of 2 (what was on its way
    on the first connection is lost then), so the rogue sends until drops are counted."""
    if not native:
        monkeypatch.setenv("ROS_GZ_BRIDGE_NATIVE", "off")
    bridge = BridgeUnderAttack(ros_side, f"bytes_{native}", "max_queued_bytes:=2000000")
    rogue = RoguePublisher(bridge.fqn, STRING, sndhwm=1000)
    payload = GzString(data="x" * MB).SerializeToString()
    try:
        assert rogue.wait_subscribed(WAIT)
        time.sleep(0.3)  # the subscription reaches the rogue before the bridge reads the pipe
        deadline = time.monotonic() + WAIT
        while int(bridge.values().get("dropped", "0")) == 0 and time.monotonic() < deadline:
            for _ in range(100):
                rogue.send(payload)
            time.sleep(0.2)
        assert int(bridge.values().get("dropped", "0")) > 0, "no drop counted"
    finally:
        rogue.close()
        bridge.close()
    output = bridge.process.output()
    assert "message(s) dropped so far" in output
    assert f"the last from {rogue.address}" in output
    assert "at most 1000 messages and 2000000 bytes (parameter max_queued_bytes)" in output


def test_undecodable_and_malformed_messages_are_counted_exactly(
    bridge: BridgeUnderAttack,
) -> None:
    """Issue 14, point 3: the channel's error count equals the number of bad messages sent,
    each under what was wrong; a warning names each kind."""
    rogue = RoguePublisher(bridge.fqn, STRING, sndhwm=10_000)
    sent = {"undecodable payload": 250, "malformed frame": 240, "wrong type": 10}
    fqn = bridge.fqn.encode()
    try:
        assert rogue.wait_subscribed(WAIT)
        time.sleep(0.3)  # the subscription reaches the rogue before the bridge reads the pipe
        for index in range(sent["undecodable payload"]):
            rogue.send(b"\x0a\xff\xff")  # a string longer than the payload
            if index % 50 == 49:
                time.sleep(0.01)
        for index in range(sent["malformed frame"]):
            if index % 2:
                rogue.send_frames([fqn, rogue.address.encode(), b"three frames"])
            else:
                rogue.send_frames([fqn, rogue.address.encode(), b"", b"\xff\xfe"])
            if index % 50 == 49:
                time.sleep(0.01)
        for _ in range(sent["wrong type"]):
            rogue.send(message_class("gz.msgs.Int32")(data=3).SerializeToString(), "gz.msgs.Int32")
        bridge.wait_for_value("errors", str(sum(sent.values())))
        time.sleep(1.0)  # nothing counted twice, nothing late
    finally:
        rogue.close()
    values = bridge.values()
    assert values["errors"] == str(sum(sent.values()))
    assert {reason: int(values[f"errors: {reason}"]) for reason in sent} == sent
    assert values["published"] == "0"
    output = bridge.process.output()
    for reason in sent:
        assert f"message skipped ({reason})" in output


def test_a_fake_peers_300_addresses_cost_nothing_once_it_is_silent(
    bridge: BridgeUnderAttack,
) -> None:
    """Issue 14, point 4: a fake peer advertises 300 addresses on the topic where nothing
    answers (150 refuse connections; 150 accept and close at once, so we can count the
    attempts); it then falls silent. Its records expire after 3 s and the bridge disconnects:
    10 s after the silence no connection attempt arrives, and the bridge's idle CPU is back
    near its baseline before the flood: within 1 percentage point or a quarter of it, whichever
    is more (the campaign saw 2.9% -> 9.4% for good; late in the whole suite the baseline itself
    was 5.7% and a settled bridge 6.7%). CPU is the bridge's own (utime + stime from /proc) over
    4 s windows, each holding two of its 2 s explanation rounds; a window can still catch one
    round more than another, so a last window over the bound is measured once more."""
    time.sleep(2.0)  # the bridge's start-up is over
    baseline = cpu_percent(bridge.pid, 4.0)
    rss_before = usage(bridge.pid).rss_bytes
    traps = TrapListeners(150)
    peer = FakePeer(bridge.fqn, STRING, traps.addresses + closed_ports(150))
    try:
        wait_until(lambda: traps.accepted >= 300, WAIT, "the bridge to try the addresses")
        flood_cpu = cpu_percent(bridge.pid, 1.0)
        peer.go_silent()
        silent_at = time.monotonic()
        time.sleep(7.0)  # expiry after 3 s of silence, then the disconnects
        settled = traps.accepted
        bound = max(baseline + 1.0, baseline * 1.25)
        after = cpu_percent(bridge.pid, 4.0)
        if after > bound:
            after = cpu_percent(bridge.pid, 4.0)
        late = traps.accepted - settled
        elapsed = time.monotonic() - silent_at
    finally:
        traps.close()
    rss_after = usage(bridge.pid).rss_bytes
    print(  # the figures for the report
        f"\nCPU baseline {baseline:.2f}%, during the flood {flood_cpu:.2f}%, "
        f"{elapsed:.0f} s after the silence {after:.2f}%; attempts during the flood "
        f"{settled}, after {late}; RSS before {rss_before / MB:.1f} MB, after "
        f"{rss_after / MB:.1f} MB"
    )
    assert elapsed >= 10
    assert late == 0
    assert after <= bound
