"""The attack suite: hostile payloads from a rogue publisher beside real ones, and what each did.

``python -m benchmarks.attacks`` runs each attack against a bridge on the native path (the
default) and on the Python path (``ROS_GZ_BRIDGE_NATIVE=off``) and writes the figures to the
"Attacks" section of SOAK.md; ``tests/faults/test_attacks.py`` runs a few seconds of each and
asserts the bounds that are not timing.

What runs, all on loopback, on discovery ports of its own: the bridge (``/amp_clock`` Clock,
``/amp_odom`` Odometry and ``/amp_tf`` TFMessage from Pose_V, Gazebo -> ROS); the real
Fortress peer publishing Clock at 500 Hz and Odometry at 50 Hz (its ``child_frame_id`` is
``real``, so its messages are told from the rogue's on ROS); one rclpy process counting what
reaches ROS (``testing/attack_ros.py``). A rogue ZeroMQ publisher that advertises itself
through valid discovery (``testing/rogue.py``) then sends, one attack after the other:

- ``padded_odometry``: an Odometry padded with a 32 MB unknown field, as fast as ZeroMQ sends
  them (the rogue's send queue holds two and its sends wait for room: it never buffers more,
  and it sends no faster than the bridge's side of the connection takes them);
- ``empty_poses``: a Pose_V of 4 M empty poses (8 MB), twice a second, on ``/amp_tf``;
- ``unknown_fields``: an Odometry followed by 768 KiB of 3-byte unknown fields, 20 a second;
- ``oversize_frames``: an Odometry padded to 200 MB, over the largest message the bridge takes
  (``GZ_TRANSPORT_MAX_MESSAGE_SIZE``, 128 MiB), 20 a second: libzmq drops the connection as it
  reads the frame's size, before buffering it, and the bridge reconnects after a delay that
  grows to 5 s.

Per attack: the messages the rogue sent, the real /clock and Odometry messages that reached ROS
during it (percent of the publishers' nominal rates), the bridge's CPU during it, its peak RSS
above its resting size (before the first attack), its RSS ``after`` seconds after the attack,
above the same resting size, and how long after the attack its RSS was first back within
``settle_mb`` of that size (None: not within ``SETTLE_LIMIT`` seconds). On a loaded machine the
bridge may still be reading the rogue's queued frames ``after`` seconds on; the settling time
says whether it gives the memory back, whatever the load.
"""

from __future__ import annotations

import json
import os
import re
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import zmq

from ros_gz_bridge_py.app.settings import NATIVE_ENV
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport.names import fully_qualified_name
from testing.e2e_harness import PARAMETER_BRIDGE, ProcessGroup, lines
from testing.gzpeer import peer_binary
from testing.procstat import MB, PeakRss, cpu_seconds, rss_mb
from testing.rogue import RoguePublisher
from testing.soak import soak_env

ROOT = Path(__file__).resolve().parent.parent
ROS_SIDE = Path(__file__).resolve().parent / "attack_ros.py"
CLOCK, ODOM, TF = "/amp_clock", "/amp_odom", "/amp_tf"
#: A ROS log line ("[WARN] [1795988267.179061441] [ros_gz_bridge]: ...").
LOG_LINE = re.compile(r"\[(DEBUG|INFO|WARN|ERROR|FATAL)\] \[")
CLOCK_HZ, ODOM_HZ = 500, 50
ODOM_TEXT = (
    'header { stamp { sec: 7 } data { key: "child_frame_id" value: "real" } } '
    "pose { position { x: 1.5 } }"
)
#: Seconds to wait for the bridge, the peers and the ROS side to be connected.
START_LIMIT = 60.0
#: Seconds after an attack to wait for the bridge's RSS to be back near its resting size.
SETTLE_LIMIT = 30.0
#: How often the RSS is read while it settles.
SETTLE_PERIOD = 0.1


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def _odometry() -> bytes:
    odom = message_class("gz.msgs.Odometry")()
    odom.header.stamp.sec = 9
    odom.pose.position.x = 2.5
    return bytes(odom.SerializeToString())


def padded_odometry(size: int) -> bytes:
    """An Odometry and one unknown length-delimited field (number 1000) of ``size`` bytes."""
    return _odometry() + _varint(1000 << 3 | 2) + _varint(size) + bytes(size)


def empty_poses(count: int) -> bytes:
    """A Pose_V of ``count`` empty poses (field 2, length 0: two bytes each)."""
    return b"\x12\x00" * count


def small_unknown_fields(size: int) -> bytes:
    """An Odometry followed by ``size`` bytes of unknown varint fields (number 1000, 3 bytes
    each with a one-byte value)."""
    field_bytes = _varint(1000 << 3) + b"\x01"
    return _odometry() + field_bytes * (size // len(field_bytes))


@dataclass(frozen=True)
class Attack:
    name: str
    topic: str
    msg_type: str
    payload: bytes
    #: Messages per second; 0: as fast as ZeroMQ takes them.
    per_second: float


#: The padding of ``oversize_frames``: over the 128 MiB input limit.
OVERSIZE_MB = 200


def attacks(padding_mb: int = 32) -> list[Attack]:
    padded = padded_odometry(padding_mb << 20)
    return [
        Attack("padded_odometry", ODOM, "ignition.msgs.Odometry", padded, 0.0),
        Attack("empty_poses", TF, "ignition.msgs.Pose_V", empty_poses(4 << 20), 2.0),
        Attack(
            "unknown_fields", ODOM, "ignition.msgs.Odometry", small_unknown_fields(768 << 10), 20
        ),
        Attack(
            "oversize_frames",
            ODOM,
            "ignition.msgs.Odometry",
            padded_odometry(OVERSIZE_MB << 20),
            20,
        ),
    ]


@dataclass
class Outcome:
    """What one attack did to one bridge."""

    attack: str
    path: str
    seconds: float
    sent: int
    clock_percent: float
    odom_percent: float
    cpu_percent: float
    resting_mb: float
    peak_above_mb: float
    after_above_mb: float
    #: Seconds from the attack's end until the RSS was first within ``settle_mb`` of resting;
    #: None if it was not within ``SETTLE_LIMIT`` seconds.
    settled_s: float | None
    #: The largest serialized message of each topic on ROS so far.
    largest: dict[str, int] = field(default_factory=dict)
    bridge_alive: bool = True


class AttackRun:
    """One bridge (one path) and its real peers, attacked in turn."""

    def __init__(
        self, native: bool, *, seconds: float, after: float, settle_mb: float = 50.0
    ) -> None:
        self.path = "native" if native else "python"
        self.seconds = seconds
        self.after = after
        self.settle_mb = settle_mb
        self.env = soak_env()
        # the bridge runs this tree's package, whichever checkout the venv was installed from
        path = self.env.get("PYTHONPATH")
        self.env["PYTHONPATH"] = f"{ROOT}{os.pathsep}{path}" if path else str(ROOT)
        if not native:
            self.env[NATIVE_ENV] = "off"
        self.group = ProcessGroup()
        self.outcomes: list[Outcome] = []
        self.status_table = ""
        self.resting = 0.0
        #: The real /clock publisher's message file (removed when the run ends).
        self.clock_file = ROOT / ".build" / f"attack-clock-{uuid.uuid4().hex[:6]}.pb"

    def run(self, chosen: list[Attack]) -> list[Outcome]:
        saved = dict(os.environ)
        os.environ.update(self.env)  # the rogue's discovery reads the environment
        try:
            self._start()
            self.resting = self._resting()
            for attack in chosen:
                self.outcomes.append(self._attack(attack))
                if not self.outcomes[-1].bridge_alive:
                    break
            self._status()
        finally:
            self.group.stop()
            self.clock_file.unlink(missing_ok=True)
            os.environ.clear()
            os.environ.update(saved)
        return self.outcomes

    def _start(self) -> None:
        clock_file = self.clock_file
        clock_file.parent.mkdir(exist_ok=True)
        clock_file.write_bytes(message_class("gz.msgs.Clock")().SerializeToString())
        lifetime = str(int(2 * START_LIMIT + 3 * (self.seconds + self.after + 30)))
        self.bridge = self.group.start(
            [
                str(PARAMETER_BRIDGE),
                f"{CLOCK}@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
                f"{ODOM}@nav_msgs/msg/Odometry[gz.msgs.Odometry",
                f"{TF}@tf2_msgs/msg/TFMessage[gz.msgs.Pose_V",
            ],
            self.env,
        )
        peer = str(peer_binary())
        self.group.start(
            [
                peer, "kind-pub", CLOCK, "ignition.msgs.Clock", str(clock_file), lifetime,
                "--stamp", "sim", "--hz", str(CLOCK_HZ), "--wait", str(START_LIMIT),
            ],
            self.env,
        )  # fmt: skip
        self.group.start(
            [
                peer,
                "pub",
                ODOM,
                "ignition.msgs.Odometry",
                str(ODOM_HZ),
                "0",
                ODOM_TEXT,
                "--wait",
                "0",
            ],
            self.env,
        )
        spec = {"clock": CLOCK, "odom": ODOM, "tf": TF, "seconds": float(lifetime)}
        self.ros = self.group.start([sys.executable, str(ROS_SIDE), json.dumps(spec)], self.env)
        deadline = time.monotonic() + START_LIMIT
        while time.monotonic() < deadline:
            counts = self._counts()
            if counts.get("clock", 0) > CLOCK_HZ and counts.get("odom_real", 0) > ODOM_HZ:
                time.sleep(2.0)  # the bridge settles at its resting size
                return
            time.sleep(0.25)
        msg = f"the {self.path} bridge did not carry the real publishers within {START_LIMIT} s"
        raise RuntimeError(msg + "\n" + self.bridge.output()[-3000:])

    def _resting(self) -> float:
        """The bridge's RSS at rest: the least of five samples 0.2 s apart."""
        samples = []
        for _ in range(5):
            samples.append(rss_mb(self.bridge.pid))
            time.sleep(0.2)
        return min(samples)

    def _counts(self, before: float | None = None) -> dict[str, Any]:
        """The ROS side's newest counts (at or before ``before``)."""
        records = [json.loads(line) for line in lines(self.ros, "COUNTS ")]
        if before is not None:
            records = [r for r in records if r["t"] <= before]
        return records[-1] if records else {}

    def _counts_at(self, moment: float) -> dict[str, Any]:
        time.sleep(max(0.0, moment + 0.3 - time.monotonic()))  # printed every 0.25 s
        return self._counts(before=moment + 0.25)

    def _attack(self, attack: Attack) -> Outcome:
        pid = self.bridge.pid
        resting = self.resting
        fqn = fully_qualified_name(self.env["GZ_PARTITION"], "", attack.topic)
        rogue = RoguePublisher(fqn, attack.msg_type, sndhwm=2)
        rogue.xpub.setsockopt(zmq.XPUB_NODROP, 1)  # a full queue makes send wait, not drop
        rogue.xpub.setsockopt(zmq.SNDTIMEO, 1000)
        sent = 0
        try:
            if not rogue.wait_subscribed(20.0):
                msg = f"the {self.path} bridge never connected to the rogue on {attack.topic}"
                raise RuntimeError(msg)
            peak = PeakRss(pid)
            start, cpu_start = time.monotonic(), cpu_seconds(pid)
            view = memoryview(attack.payload)
            period = 1.0 / attack.per_second if attack.per_second else 0.0
            next_send = start
            while (now := time.monotonic()) < start + self.seconds:
                if period and now < next_send:
                    time.sleep(min(next_send - now, 0.01))
                    continue
                try:
                    rogue.send(view)
                except zmq.Again:  # the bridge took nothing for a second
                    continue
                sent += 1
                next_send += period
            end, cpu_end = time.monotonic(), cpu_seconds(pid)
        finally:
            rogue.close()
        after, settled = self._settle(end, resting)
        highest = peak.stop() / MB
        first, last = self._counts_at(start), self._counts_at(end)
        span = end - start

        def percent(key: str, hz: int) -> float:
            return round(100 * (int(last[key]) - int(first[key])) / (hz * span), 1)

        return Outcome(
            attack=attack.name,
            path=self.path,
            seconds=round(span, 1),
            sent=sent,
            clock_percent=percent("clock", CLOCK_HZ),
            odom_percent=percent("odom_real", ODOM_HZ),
            cpu_percent=round(100 * (cpu_end - cpu_start) / span, 1),
            resting_mb=round(resting, 1),
            peak_above_mb=round(highest - resting, 1),
            after_above_mb=round(after - resting, 1),
            settled_s=None if settled is None else round(settled, 1),
            largest=dict(self._counts().get("largest", {})),
            bridge_alive=self.bridge.poll() is None,
        )

    def _settle(self, end: float, resting: float) -> tuple[float, float | None]:
        """The RSS ``after`` seconds past ``end``, and the seconds past ``end`` at which the RSS
        was first within ``settle_mb`` of ``resting`` (read until both are known, at most
        ``SETTLE_LIMIT`` seconds past ``end``)."""
        after: float | None = None
        settled: float | None = None
        while self.bridge.poll() is None:
            now = time.monotonic()
            rss = rss_mb(self.bridge.pid)
            if settled is None and rss - resting < self.settle_mb:
                settled = now - end
            if after is None and now >= end + self.after:
                after = rss
            if after is not None and (settled is not None or now >= end + SETTLE_LIMIT):
                return after, settled
            time.sleep(SETTLE_PERIOD)
        return 0.0, settled

    def _status(self) -> None:
        """The bridge's status table (SIGUSR1), for the report."""
        if self.bridge.poll() is not None:
            return
        self.bridge.send_signal(10)  # SIGUSR1
        time.sleep(1.0)
        self.status_table = status_table(self.bridge.output())


def status_table(output: str) -> str:
    """The last status table in a bridge's ``output``, without the log lines printed while it
    was (they would read as rows of it)."""
    lines = output.splitlines()
    heads = [i for i, line in enumerate(lines) if line.startswith("LEVEL ")]
    table = lines[heads[-1] :] if heads else []
    return "\n".join(line for line in table if not LOG_LINE.match(line))
