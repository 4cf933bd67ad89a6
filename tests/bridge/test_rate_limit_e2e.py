"""``max_rate`` (issue 16, point 5): a 100 Hz stream limited to 10 Hz arrives at 10 Hz (within
10%), in either direction, and the drops are counted in ``/diagnostics``.

Gazebo -> ROS: the C++ Fortress peer publishes at 100 Hz; the YAML entry says ``max_rate: 10``.
ROS -> Gazebo: an rclpy publisher sends at about 100 Hz to a command-line bridge, limited by the
node's ``max_rate`` parameter (20), and a Fortress subscriber counts what arrives.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from std_msgs.msg import String

from testing.behaviour_harness import WAIT, RosSide, bridge_command, probe, started
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)

__all__ = ["probe", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

WINDOW = 4.0


def _statuses(diagnostics: list[DiagnosticArray], ros_topic: str) -> list[dict[str, str]]:
    return [
        {kv.key: kv.value for kv in status.values}
        for array in diagnostics
        for status in array.status
        if status.name.endswith(f" {ros_topic}")
    ]


def test_a_100_hz_stream_limited_to_10_hz_arrives_at_10_hz(
    probe: RosSide, started: list[PeerProcess], tmp_path: Path
) -> None:
    require_peer()
    down, up = unique_name("rate_down"), unique_name("rate_up")
    config = tmp_path / "rates.yaml"
    config.write_text(
        f"- topic_name: {down}\n  ros_type_name: std_msgs/msg/String\n"
        "  gz_type_name: gz.msgs.StringMsg\n  direction: GZ_TO_ROS\n  max_rate: 10\n"
    )
    started.append(
        start_peer(
            "pub", down, "ignition.msgs.StringMsg", "100", "0", 'data: "d"', "--wait", "0"
        )
    )  # fmt: skip
    echo = start_peer("echo", up, "ignition.msgs.StringMsg", "60")
    started.append(echo)
    bridge = start_process(
        bridge_command(
            f"{up}@std_msgs/msg/String]gz.msgs.StringMsg",
            ros_args=[
                "-p", f"config_file:={config}",
                "-p", "max_rate:=20",
                "-p", "status_period:=1",
            ],
        )
    )  # fmt: skip
    started.append(bridge)
    wait_for_line(bridge, r"Creating ROS->GZ", timeout=30)
    arrays: list[DiagnosticArray] = []
    probe.run(
        lambda: probe.node.create_subscription(DiagnosticArray, "/diagnostics", arrays.append, 10)
    )
    received, _ = probe.subscribe(String, down)
    received.wait_for_count(3, WAIT)
    publisher = probe.run(lambda: probe.node.create_publisher(String, up, 10))
    wait_until(lambda: probe.count_subscribers(up) >= 1, WAIT, f"the bridge on {up}")
    stop = threading.Event()

    def publish_at_100_hz() -> None:
        message, next_time = String(data="u"), time.monotonic()
        while not stop.is_set():
            probe.run(lambda: publisher.publish(message))
            next_time += 0.01
            time.sleep(max(0.0, next_time - time.monotonic()))

    sender = threading.Thread(target=publish_at_100_hz, daemon=True)
    sender.start()
    try:
        time.sleep(1.0)  # let both directions settle
        down_before, up_before = len(received.items()), echo.output().count("MSG ")
        time.sleep(WINDOW)
        down_rate = (len(received.items()) - down_before) / WINDOW
        up_rate = (echo.output().count("MSG ") - up_before) / WINDOW
    finally:
        stop.set()
        sender.join(2)
    assert 9.0 <= down_rate <= 11.0, f"Gazebo->ROS arrived at {down_rate:.1f} Hz"
    assert 18.0 <= up_rate <= 22.0, f"ROS->Gazebo arrived at {up_rate:.1f} Hz"
    wait_until(lambda: bool(_statuses(arrays, up)), WAIT, "a /diagnostics status of the bridge")
    for topic in (down, up):
        last = _statuses(arrays, topic)[-1]
        received_total, limited = int(last["received"]), int(last["rate_limited"])
        assert limited > 0.7 * received_total, f"{topic}: {last}"
        # The counters are read while messages flow: one may be in between.
        assert abs(int(last["published"]) + limited - received_total) <= 1
