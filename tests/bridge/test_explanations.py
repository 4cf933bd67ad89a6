"""The bridge says why a topic carries nothing, and ``parameter_bridge --check`` reports it.

Each cause of issue 12 point 3 is made real: a real Fortress publisher of another type, a
typed Fortress subscriber of another type, a publisher in another partition (the C++ peer
and its ``IGN_PARTITION``), an rclpy subscriber of another type, one with incompatible QoS,
and no Gazebo process at all (a bridge on discovery ports nobody else uses). Each explanation
must appear within 10 s of its cause and be logged at most twice while the cause lasts; the
check command names each one and exits 1.
"""

from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import time
from collections.abc import Iterator
from dataclasses import dataclass

import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import Int32, String

from testing.behaviour_harness import WAIT, RosSide, bridge_command, started
from testing.e2e_harness import PARAMETER_BRIDGE
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
)

__all__ = ["started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer, pytest.mark.slow]

#: Issue 12: each explanation within 10 s of its cause.
EXPLAIN_WITHIN = 10.0
#: How long the bridge keeps running with every cause in place, to count repeats.
DWELL = 12.0
OTHER_PARTITION = f"elsewhere-{os.getpid()}"
#: Seconds a typed subscriber stays before it leaves: past the explainer's warm-up.
SUBSCRIBED_FOR = 6


@dataclass(frozen=True)
class Topics:
    wrong_gz_publisher: str
    wrong_gz_subscriber: str
    other_partition: str
    wrong_ros_type: str
    wrong_ros_qos: str

    @classmethod
    def make(cls) -> Topics:
        return cls(
            *(unique_name(stem) for stem in ("xp_pub", "xp_sub", "xp_part", "xp_rt", "xp_qos"))
        )

    def arguments(self) -> list[str]:
        return [
            f"{self.wrong_gz_publisher}@geometry_msgs/msg/PoseArray[gz.msgs.Pose_V",
            f"{self.wrong_gz_subscriber}@geometry_msgs/msg/Twist]gz.msgs.Twist",
            f"{self.other_partition}@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
            f"{self.wrong_ros_type}@std_msgs/msg/String[gz.msgs.StringMsg",
            f"{self.wrong_ros_qos}@std_msgs/msg/String[gz.msgs.StringMsg",
        ]


#: What each cause's explanation must say (a regular expression over one log line).
def expected(topics: Topics) -> dict[str, str]:
    return {
        "gazebo publisher of another type": (
            rf"{re.escape(topics.wrong_gz_publisher)}.*publishes ignition\.msgs\.Pose, but the "
            r"bridge is configured with gz\.msgs\.Pose_V; gz\.msgs\.Pose pairs with "
            r"geometry_msgs/msg/Pose"
        ),
        "gazebo subscriber of another type": (
            rf"subscriber of {re.escape(topics.wrong_gz_subscriber)} .*did not take "
            r"gz\.msgs\.Twist under either spelling"
        ),
        "topic in another partition": (
            rf"{re.escape(topics.other_partition)} is alive in another partition "
            rf"\('{OTHER_PARTITION}': publisher ignition\.msgs\.Clock\).*"
            rf"GZ_PARTITION={OTHER_PARTITION}"
        ),
        "ROS subscriber of another type": (
            rf"ROS subscriber /xp_probe of {re.escape(topics.wrong_ros_type)} uses "
            r"std_msgs/msg/Int32, but the bridge is configured with std_msgs/msg/String"
        ),
        "ROS subscriber with incompatible QoS": (
            rf"ROS subscriber /xp_probe of {re.escape(topics.wrong_ros_qos)} cannot match the "
            r"bridge's QoS: .*[Vv]olatile publisher and transient local"
        ),
    }


def start_causes(topics: Topics, ros: RosSide, processes: list[PeerProcess]) -> float:
    """Put every cause in place; returns when the last one is: the Fortress processes have
    their endpoints (READY), which on a busy machine can take seconds after they start."""
    env = dict(os.environ, IGN_PARTITION=OTHER_PARTITION, GZ_PARTITION=OTHER_PARTITION)
    peers = [
        start_peer(
            "pub", topics.wrong_gz_publisher, "ignition.msgs.Pose", "5", "0", "", "--wait", "0"
        ),
        start_peer("echo", topics.wrong_gz_subscriber, "ignition.msgs.Vector3d", "60"),
        start_peer(
            "pub", topics.other_partition, "ignition.msgs.Clock", "5", "0", "sim { sec: 1 }",
            "--wait", "0", env=env,
        ),
    ]  # fmt: skip
    processes.extend(peers)
    for peer in peers:
        wait_for_line(peer, r"^READY$", timeout=3 * WAIT)
    ros.run(lambda: ros.node.create_subscription(Int32, topics.wrong_ros_type, lambda _: None, 10))
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    ros.run(
        lambda: ros.node.create_subscription(String, topics.wrong_ros_qos, lambda _: None, latched)
    )
    return time.monotonic()


@pytest.fixture
def probe() -> Iterator[RosSide]:
    """The ROS side, as a node named ``xp_probe`` (the explanations name it)."""
    side = RosSide("xp_probe")
    yield side
    side.close()


def test_each_cause_is_explained_within_10_s_and_not_repeated(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    topics = Topics.make()
    bridge = start_process(bridge_command(*topics.arguments()))
    started.append(bridge)
    wait_for_line(bridge, r"Creating ROS->GZ", timeout=30)
    caused = start_causes(topics, probe, started)
    patterns = expected(topics)
    for cause, pattern in patterns.items():
        remaining = caused + EXPLAIN_WITHIN - time.monotonic()
        assert remaining > 0, f"out of time before checking: {cause}"
        wait_for_line(bridge, pattern, timeout=remaining)
    time.sleep(max(0.0, caused + DWELL - time.monotonic()))
    output = bridge.output()
    for cause, pattern in patterns.items():
        said = len(re.findall(pattern, output))
        assert 1 <= said <= 2, f"{cause}: said {said} times\n{output}"


def test_check_reports_each_cause_and_exits_1(probe: RosSide, started: list[PeerProcess]) -> None:
    require_peer()
    topics = Topics.make()
    check = start_process(bridge_command("--check", "6", *topics.arguments()))
    started.append(check)
    wait_for_line(check, r"^Listening for 6 s", timeout=30)
    start_causes(topics, probe, started)
    assert check.wait(30) == 1, check.output()
    output = check.output()
    for cause, pattern in expected(topics).items():
        assert re.search(rf"PROBLEM: .*{pattern}", output), f"{cause} not reported:\n{output}"
    assert "0 of 5 checked can carry messages" in output


def _unused_ports() -> dict[str, str]:
    """Discovery ports no other test uses: nobody else is heard."""
    msg = random.randrange(20000, 40000, 2)
    ports = {"DISCOVERY_MSG_PORT": str(msg), "DISCOVERY_SRV_PORT": str(msg + 1)}
    return {prefix + name: value for name, value in ports.items() for prefix in ("GZ_", "IGN_")}


def test_no_gazebo_peer_is_said_once_with_where_the_bridge_listens(
    started: list[PeerProcess],
) -> None:
    env = dict(os.environ, **_unused_ports())
    topic = unique_name("xp_alone")
    bridge = start_process(bridge_command(f"{topic}@std_msgs/msg/String[gz.msgs.StringMsg",
                                          f"{topic}_2@std_msgs/msg/String[gz.msgs.StringMsg"),
                           env)  # fmt: skip
    started.append(bridge)
    pattern = (
        r"Nothing can flow: no Gazebo Transport process is heard at all; the bridge listens "
        rf"with ZeroMQ discovery on 239\.255\.0\.7 ports {env['GZ_DISCOVERY_MSG_PORT']} .*"
        r"partition '.+'.*GZ_PARTITION"
    )
    wait_for_line(bridge, pattern, timeout=EXPLAIN_WITHIN + 5)  # + the bridge's start-up
    time.sleep(DWELL)
    assert len(re.findall(pattern, bridge.output())) == 1, bridge.output()
    env = dict(os.environ, **_unused_ports())  # alone again: the bridge above is a peer
    done = subprocess.run(
        [str(PARAMETER_BRIDGE), "--check", "3", f"{topic}@std_msgs/msg/String]gz.msgs.StringMsg"],
        env=env, capture_output=True, text=True, timeout=WAIT * 3, check=False,
    )  # fmt: skip
    assert done.returncode == 1, done.stdout + done.stderr
    assert "PROBLEM: no Gazebo Transport process is heard at all" in done.stdout


def test_a_subscriber_of_our_type_that_left_is_not_one_of_another_type(
    started: list[PeerProcess],
) -> None:
    """A typed Fortress subscriber that took the bridge's Twist and exits: the bridge waits
    for Gazebo again and says so, and never that the subscriber expects another type (it did,
    in the seconds between its END_CONNECTION and its process's expiry)."""
    require_peer()
    topic = unique_name("xp_left")
    bridge = start_process(bridge_command(f"{topic}@geometry_msgs/msg/Twist]gz.msgs.Twist"))
    started.append(bridge)
    wait_for_line(bridge, r"Creating ROS->GZ", timeout=30)
    echo = start_peer("echo", topic, "ignition.msgs.Twist", str(SUBSCRIBED_FOR))
    started.append(echo)  # its SUBSCRIBE reaches the bridge, then it takes the Twist
    echo.wait(SUBSCRIBED_FOR + WAIT)
    left = len(bridge.output())
    deadline = time.monotonic() + EXPLAIN_WITHIN
    while f"no Gazebo subscriber of {topic}" not in bridge.output()[left:]:
        assert time.monotonic() < deadline, bridge.output()
        bridge.send_signal(signal.SIGUSR1)  # the status table: its why lines at this moment
        time.sleep(0.3)
    assert "did not take" not in bridge.output()


def test_a_killed_subscriber_is_no_subscriber_any_more(started: list[PeerProcess]) -> None:
    """A Fortress subscriber killed (no END_CONNECTION, no BYE) was kept as registered for
    good: the channel showed "flowing" or "waiting for ROS" to nobody (found by a new user
    restarting a simulator)."""
    require_peer()
    topic = unique_name("xp_killed")
    bridge = start_process(bridge_command(f"{topic}@geometry_msgs/msg/Twist]gz.msgs.Twist"))
    started.append(bridge)
    wait_for_line(bridge, r"Creating ROS->GZ", timeout=30)
    echo = start_peer("echo", topic, "ignition.msgs.Twist", "120")
    started.append(echo)

    def row_shows(flow: str) -> bool:
        """Whether the status table printed now shows ``flow`` for the channel."""
        left = len(bridge.output())
        bridge.send_signal(signal.SIGUSR1)
        time.sleep(0.3)
        row = re.compile(rf"^\S+\s+ROS->GZ\s+{re.escape(topic)}\s.*{flow}", re.MULTILINE)
        return bool(row.search(bridge.output()[left:]))

    deadline = time.monotonic() + EXPLAIN_WITHIN + WAIT
    while not row_shows("waiting for ROS"):  # registered: it waits for a ROS publisher
        assert time.monotonic() < deadline, bridge.output()
    echo.kill()
    echo.wait(WAIT)
    deadline = time.monotonic() + EXPLAIN_WITHIN
    while not row_shows("waiting for Gazebo"):
        assert time.monotonic() < deadline, bridge.output()


def test_check_without_problems_exits_0(started: list[PeerProcess]) -> None:
    require_peer()
    topic = unique_name("xp_fine")
    started.append(
        start_peer("pub", topic, "ignition.msgs.StringMsg", "5", "0", 'data: "x"', "--wait", "0")
    )
    done = subprocess.run(
        [str(PARAMETER_BRIDGE), "--check", "3", f"{topic}@std_msgs/msg/String[gz.msgs.StringMsg"],
        capture_output=True, text=True, timeout=WAIT * 3, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert "publisher (ignition.msgs.StringMsg)" in done.stdout
    assert "1 of 1 checked can carry messages" in done.stdout


def test_check_argument_errors() -> None:
    done = subprocess.run(
        [str(PARAMETER_BRIDGE), "--check", "soon", "/a@std_msgs/msg/String@gz.msgs.StringMsg"],
        capture_output=True, text=True, timeout=WAIT * 3, check=False,
    )  # fmt: skip
    assert done.returncode == 255
    assert "--check takes a number of seconds > 0" in done.stderr
