"""Live status: ``/diagnostics`` lists every channel with exact counters; SIGUSR1 prints a table.

One ``parameter_bridge`` process (``status_period:=0.5``) bridges a String and an Image topic
Gazebo -> ROS, a String topic ROS -> Gazebo, a service, and a lazy topic nobody reads. The
Gazebo side is our ``ZmqGzNode``, the ROS side an rclpy node. Counters are cumulative, so each
count check first lets the channel settle after its warm-up messages (the first messages after
discovery may be lost) and then compares the increase with exactly what the test sent.
"""

from __future__ import annotations

import re
import signal
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs.msg import Image
from std_msgs.msg import String

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_node,
    publish_until,
    ros_side,
    start_bridge,
)
from testing.gzpeer import Inbox, PeerProcess, unique_name, wait_for_line, wait_until

__all__ = ["gz_node", "ros_side"]

pytestmark = [pytest.mark.ros]

IMAGE = "ignition.msgs.Image"
GzString = message_class(STRING)
GzImage = message_class(IMAGE)
#: gz PixelFormatType RGB_INT8; 0 (UNKNOWN_PIXEL_FORMAT) has no ROS encoding.
RGB_INT8 = 3
UNKNOWN_PIXEL_FORMAT = 0


class Setup:
    """The bridge process, its topics and the /diagnostics arrays it published."""

    def __init__(self, tmp: Path) -> None:
        self.string = unique_name("status_string")
        self.image = unique_name("status_image")
        self.to_gz = unique_name("status_to_gz")
        self.service = unique_name("status_service")
        self.lazy = unique_name("status_lazy")
        self.node_name = unique_name("status_bridge").lstrip("/")
        config = tmp / "lazy.yaml"
        config.write_text(
            f"- topic_name: {self.lazy}\n"
            "  ros_type_name: std_msgs/msg/String\n"
            f"  gz_type_name: {STRING}\n"
            "  direction: GZ_TO_ROS\n"
            "  lazy: true\n"
        )
        self.bridge: PeerProcess = start_bridge(
            f"{self.string}@std_msgs/msg/String[{STRING}",
            f"{self.image}@sensor_msgs/msg/Image[{IMAGE}",
            f"{self.to_gz}@std_msgs/msg/String]{STRING}",
            f"{self.service}@ros_gz_interfaces/srv/ControlWorld",
            ros_args=[
                "-r",
                f"__node:={self.node_name}",
                "-p",
                "status_period:=0.5",
                "-p",
                f"config_file:={config}",
            ],
            creating=5,
        )
        self.diagnostics = Inbox()

    def name(self, direction: str, ros_name: str) -> str:
        return f"ros_gz_bridge: {direction} {ros_name}"

    def arrays(self) -> list[dict[str, Any]]:
        """Our bridge's arrays so far, oldest first, each as {status name: DiagnosticStatus}."""
        return [
            {status.name: status for status in array.status}
            for array, _ in self.diagnostics.items()
            if array.status and array.status[0].hardware_id == f"/{self.node_name}"
        ]

    def wait_for_arrays(self, count: int) -> list[dict[str, Any]]:
        wait_until(lambda: len(self.arrays()) >= count, WAIT, f"{count} /diagnostics arrays")
        return self.arrays()


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory, ros_side: RosSide) -> Iterator[Setup]:
    status = Setup(tmp_path_factory.mktemp("status"))
    subscription = ros_side.run(
        lambda: ros_side.node.create_subscription(
            DiagnosticArray, "/diagnostics", lambda m: status.diagnostics(m, None), 10
        )
    )
    yield status
    ros_side.destroy(subscription)
    status.bridge.stop()


def values(status: Any) -> dict[str, str]:
    return {kv.key: kv.value for kv in status.values}


def counters(status: Any) -> tuple[int, int, int]:
    found = values(status)
    return int(found["received"]), int(found["published"]), int(found["conversion_errors"])


def settled(setup: Setup, name: str) -> tuple[int, int, int]:
    """The channel's counters once two consecutive arrays agree (no message in flight)."""
    start = len(setup.arrays())

    def agree() -> bool:
        arrays = setup.arrays()[start:]
        return len(arrays) >= 2 and counters(arrays[-1][name]) == counters(arrays[-2][name])

    wait_until(agree, 3 * WAIT, f"the counters of {name} to settle")
    return counters(setup.arrays()[-1][name])


def wait_for_counters(setup: Setup, name: str, expected: tuple[int, int, int]) -> list[Any]:
    """Wait for an array showing ``expected`` (received, published, errors) for ``name``."""
    seen: list[tuple[int, int, int]] = []

    def reached() -> bool:
        latest = counters(setup.arrays()[-1][name])
        seen.append(latest)
        return latest == expected

    deadline = time.monotonic() + WAIT
    while not reached():
        if time.monotonic() > deadline:
            pytest.fail(
                f"{name}: expected (received, published, errors) {expected}, saw {seen[-3:]}"
            )
        time.sleep(0.05)
    return [array[name] for array in setup.arrays()]


def heard_gazebo(status: Any) -> bool:
    """The explainer judged the channel while the bridge heard a Gazebo process."""
    heard = re.search(
        r"\((\d+) Gazebo process(es)? heard in any partition\)", values(status)["why"]
    )
    return heard is not None and int(heard.group(1)) > 0


def test_diagnostics_list_every_channel(setup: Setup, gz_node: GzNode) -> None:
    # The lazy channel's level depends on whether a Gazebo process is heard (none at all is a
    # misconfiguration, WARN); gz_node is that process, and the array checked is one the
    # explainer made after the bridge heard it.
    lazy_name = setup.name("GZ->ROS", setup.lazy)
    setup.wait_for_arrays(1)
    wait_until(
        lambda: heard_gazebo(setup.arrays()[-1][lazy_name]),
        3 * WAIT,
        "an array judging the lazy channel with a Gazebo process heard",
    )
    latest = setup.arrays()[-1]
    expected = {
        setup.name("GZ->ROS", setup.string),
        setup.name("GZ->ROS", setup.image),
        setup.name("ROS->GZ", setup.to_gz),
        setup.name("service", setup.service),
        setup.name("GZ->ROS", setup.lazy),
    }
    assert set(latest) == expected
    lazy = latest[lazy_name]
    assert lazy.level == DiagnosticStatus.STALE, values(lazy)
    assert values(lazy)["state"] == "lazy_idle"
    service = values(latest[setup.name("service", setup.service)])
    assert service["ros_type"] == "ros_gz_interfaces/srv/ControlWorld"
    assert service["received"] == "0"
    assert values(latest[setup.name("ROS->GZ", setup.to_gz)])["gz_name"] == setup.to_gz
    assert latest[setup.name("GZ->ROS", setup.string)].level == DiagnosticStatus.OK


def test_string_counts_equal_what_was_sent(
    setup: Setup, ros_side: RosSide, gz_node: GzNode
) -> None:
    name = setup.name("GZ->ROS", setup.string)
    inbox, subscription = ros_side.subscribe(String, setup.string)
    publisher = gz_node.advertise(setup.string, STRING)
    try:
        wait_until(publisher.has_connections, WAIT, "the bridge to subscribe")
        publish_until(
            lambda i: publisher.publish(GzString(data=f"warm {i}")),
            lambda: bool(inbox.items()),
            "a warm-up message reaches ROS",
        )
        before = settled(setup, name)
        sent = 7
        for index in range(sent):
            publisher.publish(GzString(data=f"data {index}"))
        inbox.wait_for(
            lambda items: sum(m.data.startswith("data") for m, _ in items) == sent,
            WAIT,
            f"{sent} data messages on ROS",
        )
        after = (before[0] + sent, before[1] + sent, before[2])
        history = wait_for_counters(setup, name, after)
    finally:
        publisher.close()
        ros_side.destroy(subscription)
    assert history[-1].level == DiagnosticStatus.OK
    assert any(float(values(status)["rate_hz"]) > 0 for status in history)


def _gz_image(height: int, pixel_format: int) -> Any:
    image = GzImage(width=2, height=height, step=6, pixel_format_type=pixel_format)
    image.data = bytes(6 * height)
    return image


def test_image_counts_include_conversion_errors(
    setup: Setup, ros_side: RosSide, gz_node: GzNode
) -> None:
    name = setup.name("GZ->ROS", setup.image)
    inbox, subscription = ros_side.subscribe(Image, setup.image)
    publisher = gz_node.advertise(setup.image, IMAGE)
    try:
        wait_until(publisher.has_connections, WAIT, "the bridge to subscribe")
        publish_until(
            lambda _i: publisher.publish(_gz_image(1, RGB_INT8)),
            lambda: bool(inbox.items()),
            "a warm-up image reaches ROS",
        )
        before = settled(setup, name)
        bad, good = 2, 3
        for _ in range(bad):
            publisher.publish(_gz_image(2, UNKNOWN_PIXEL_FORMAT))
        for _ in range(good):
            publisher.publish(_gz_image(2, RGB_INT8))
        inbox.wait_for(
            lambda items: sum(m.height == 2 for m, _ in items) == good,
            WAIT,
            f"{good} good images on ROS",
        )
        after = (before[0] + bad + good, before[1] + good, before[2] + bad)
        history = wait_for_counters(setup, name, after)
    finally:
        publisher.close()
        ros_side.destroy(subscription)
    assert "pixel_format_type" in values(history[-1])["last_error"]
    assert any(status.level == DiagnosticStatus.WARN for status in history)


def test_sigusr1_prints_the_table(setup: Setup) -> None:
    setup.wait_for_arrays(1)  # the bridge is spinning: the signal handler is installed
    setup.bridge.send_signal(signal.SIGUSR1)
    wait_for_line(setup.bridge, r"^LEVEL\s+DIRECTION\s+ROS\s+GAZEBO\s+STATE\s+IN\s+OUT")
    rows = (
        ("GZ->ROS", setup.string),
        ("GZ->ROS", setup.image),
        ("ROS->GZ", setup.to_gz),
        ("GZ->ROS", setup.lazy),
        ("service", setup.service),
    )
    for direction, topic in rows:
        wait_for_line(setup.bridge, rf"^\w+\s+{direction}\s+{re.escape(topic)}\s+\S+\s+\w+\s+\d+")
    assert setup.bridge.poll() is None
