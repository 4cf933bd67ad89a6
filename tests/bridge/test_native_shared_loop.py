"""Every native Gazebo -> ROS channel of a bridge runs on one loop (docs/native.md §5).

A fleet in one process: the bridge's thread count must not grow with its native channels, nor
with those whose payloads fall back to Python, every channel's messages must flow, and a flooded
channel must not starve a light one. The channels of small messages share one SUB socket: one
TCP connection per publisher carries all their topics, and a topic whose messages outgrow it
moves to a socket of its own. The Gazebo side
is the C++ Fortress peer (one process publishing many topics, as a simulator does); the ROS side
an rclpy node of this process; the bridge a real ``parameter_bridge`` process.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.native import extension
from testing.behaviour_harness import STRING, WAIT, RosSide, ros_side, start_bridge, started
from testing.gzpeer import PeerProcess, require_peer, start_peer, unique_name, wait_until
from testing.procstat import tcp_sockets, threads_of

__all__ = ["ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer, pytest.mark.slow]

#: Channels of the small bridge and of the large one.
SMALL, LARGE = 2, 32
#: Messages the light topic publishes beside the flood, and the share that must arrive.
LIGHT_COUNT, LIGHT_SHARE = 60, 0.9
#: The light topic's rate: a ROS subscriber starved of CPU by the flood for longer than the
#: bridge's keep-last 10 at this rate would lose messages the loop did deliver (86 of 100 at
#: 100 Hz in one full-suite run), which is not what this test is about.
LIGHT_HZ = 20
#: Seconds the light publisher waits once discovery tells it of the bridge's subscription, so
#: that the ZeroMQ subscription has reached it before its first message.
LIGHT_SETTLE = 1.0
#: What the flood sends, as fast as the peer can.
FLOOD_TEXT = "x" * 2000
#: Channels whose payloads fall back to Python at once.
FALLING = 8
#: A string with a NUL inside: valid protobuf that the transcoder leaves to the channel's
#: Python path (docs/native.md §4), which publishes it.
NUL_TEXT = 'data: "fell\\000back"'
#: Its messages each channel must deliver: the first of a new sender is judged and converted
#: by the reader on the loop's thread, the later ones fall back.
FELL = 3
#: Seconds a thread count must hold to count as settled.
THREADS_SETTLE = 1.0
#: The bridge's byte budget per queue in the growth test: the shared socket's 1000-message
#: queue then holds payloads of 1 kB within it, and the flood's 2 kB outgrow it.
SMALL_BUDGET = 1_000_000


def require_native() -> None:
    """Skip where the bridge processes take the Python path (no extension, or
    ``ROS_GZ_BRIDGE_NATIVE=off``, under which the suite also runs)."""
    if extension() is None:
        pytest.skip("the native extension is not built here")
    if os.environ.get("ROS_GZ_BRIDGE_NATIVE", "on") == "off":
        pytest.skip("ROS_GZ_BRIDGE_NATIVE=off: every channel takes the Python path")


def bridge_of(
    topics: list[str], started: list[PeerProcess], ros_args: tuple[str, ...] = ()
) -> PeerProcess:
    bridge = start_bridge(
        *(f"{topic}@std_msgs/msg/String[{STRING}" for topic in topics),
        ros_args=ros_args,
        creating=len(topics),
    )
    started.append(bridge)
    return bridge


def settled_threads(process: PeerProcess) -> int:
    """The process's thread count once it stayed the same for :data:`THREADS_SETTLE` seconds
    (Fast DDS starts some of its threads a moment after discovery)."""
    deadline = time.monotonic() + WAIT
    count = threads_of(process)
    while True:
        time.sleep(THREADS_SETTLE)
        now = threads_of(process)
        if now == count or time.monotonic() > deadline:
            return now
        count = now


def flowing(ros_side: RosSide, topics: list[str]) -> None:
    """Wait until every topic's messages reach the ROS side, with the peer's text."""
    inboxes = [ros_side.subscribe(String, topic)[0] for topic in topics]
    for topic, inbox in zip(topics, inboxes, strict=True):
        items = inbox.wait_for_count(3, WAIT * 2)
        assert items[-1][0].data == "fleet", f"{topic} carried {items[-1][0].data!r}"


def test_the_thread_count_does_not_grow_with_native_channels(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    require_native()
    base = unique_name("fleet")
    topics = [f"{base}_{i}" for i in range(LARGE)]
    started.append(start_peer("pub-many", STRING, "50", 'data: "fleet"', *topics))
    small = bridge_of(topics[:SMALL], started)
    large = bridge_of(topics[SMALL:], started)
    flowing(ros_side, topics)
    small_threads, large_threads = threads_of(small), threads_of(large)
    # One native loop for all: 30 channels cost no thread of their own (a thread per channel
    # gave the large bridge 30 more).
    assert large_threads <= small_threads + 2, (small_threads, large_threads)


def test_one_connection_carries_the_small_topics_of_a_publisher(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """A socket per topic had a TCP connection per topic to the simulator's PUB socket, each
    message a wake-up of libzmq's I/O thread and of the loop of its own; one socket for the
    channels of small messages has one connection per publishing process, as a Gazebo
    subscriber has."""
    require_peer()
    require_native()
    base = unique_name("shared")
    topics = [f"{base}_{i}" for i in range(SMALL * 4)]
    publisher = start_peer("pub-many", STRING, "50", 'data: "fleet"', *topics)
    started.append(publisher)
    bridge = bridge_of(topics, started)
    flowing(ros_side, topics)
    listening = {s.local_port for s in tcp_sockets(publisher.pid) if s.listening}
    connected = [s for s in tcp_sockets(bridge.pid) if s.established]
    assert len([s for s in connected if s.remote_port in listening]) == 1, connected


def test_a_topic_whose_messages_outgrow_the_shared_socket_takes_one_of_its_own(
    ros_side: RosSide, started: list[PeerProcess], tmp_path: Path
) -> None:
    """Within a budget of 1 MB a queue, the shared socket holds 1000 messages of 1 kB from a
    publisher: a topic whose messages are 2 kB takes a socket of its own (its receive queue
    holds what fits the budget), so the bridge holds a second connection to their publisher,
    and both topics keep flowing."""
    require_peer()
    require_native()
    grows, stays = unique_name("grows"), unique_name("stays")
    spec = tmp_path / "two.spec"
    spec.write_text(
        f'pub {STRING} 20 {stays} data: "fleet"\npub {STRING} 20 {grows} data: "{FLOOD_TEXT}"\n',
        encoding="utf-8",
    )
    publisher = start_peer("pub-fleet", str(spec), "0")
    started.append(publisher)
    bridge = bridge_of([grows, stays], started, ("-p", f"max_queued_bytes:={SMALL_BUDGET}"))
    flowing(ros_side, [stays])
    inbox = ros_side.subscribe(String, grows, 1000)[0]
    inbox.wait_for_count(10, WAIT * 2)
    assert {message.data for message, _ in inbox.items()} == {FLOOD_TEXT}
    listening = {s.local_port for s in tcp_sockets(publisher.pid) if s.listening}

    def connections() -> int:
        connected = tcp_sockets(bridge.pid)
        return len([s for s in connected if s.established and s.remote_port in listening])

    wait_until(lambda: connections() == 2, WAIT, "a socket of its own for the grown topic")
    count = len(inbox.items())
    inbox.wait_for_count(count + 10, WAIT)
    flowing(ros_side, [stays])


def test_a_flooded_channel_does_not_starve_a_light_one(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    require_native()
    flood, light = unique_name("flood"), unique_name("light")
    bridge_of([flood, light], started)
    started.append(
        start_peer("pub", flood, STRING, "100000", "0", f'data: "{FLOOD_TEXT}"', "--wait", "0")
    )
    inbox = ros_side.subscribe(String, light, 1000)[0]
    wait_until(lambda: ros_side.count_publishers(light) >= 1, WAIT, "the bridge's publisher")
    started.append(
        start_peer(
            "pub",
            light,
            STRING,
            str(LIGHT_HZ),
            str(LIGHT_COUNT),
            'data: "light"',
            "--wait",
            str(WAIT),
            "--settle",
            str(LIGHT_SETTLE),
        )
    )
    inbox.holds_within(lambda items: len(items) >= LIGHT_COUNT, WAIT + LIGHT_COUNT / LIGHT_HZ)
    received = [message.data for message, _ in inbox.items()]
    assert set(received) <= {"light"}
    assert len(received) >= LIGHT_SHARE * LIGHT_COUNT, len(received)


def test_fallbacks_on_many_channels_share_one_thread(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """A publisher whose payloads fall back on every topic of a bridge: each channel's payloads
    are converted and published by its Python path, and the bridge gains one thread for all of
    them (before: a thread per channel, 8 more here)."""
    require_peer()
    require_native()
    base = unique_name("fallen")
    topics = [f"{base}_{i}" for i in range(FALLING)]
    started.append(start_peer("pub-many", STRING, "20", 'data: "fleet"', *topics))
    bridge = bridge_of(topics, started)
    inboxes = [ros_side.subscribe(String, topic, 1000)[0] for topic in topics]
    for inbox in inboxes:
        inbox.wait_for_count(3, WAIT * 2)
    before = settled_threads(bridge)
    started.append(start_peer("pub-many", STRING, "20", NUL_TEXT, *topics))
    for topic, inbox in zip(topics, inboxes, strict=True):
        inbox.wait_for(
            lambda items: sum(message.data == "fell" for message, _ in items) >= FELL,
            WAIT * 2,
            f"{topic}: {FELL} messages that fell back",
        )
    after = settled_threads(bridge)
    assert after <= before + 1, (before, after)
    received = {message.data for inbox in inboxes for message, _ in inbox.items()}
    assert received == {"fleet", "fell"}  # a ROS string ends at its first NUL
