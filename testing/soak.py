"""The soak: the bridge under mixed traffic and faults for a while, and what it measured.

``make soak`` runs it for 10 minutes (``python -m benchmarks.soak --seconds 600``) and writes
``SOAK.md``; ``tests/faults/test_soak.py`` runs 45 s of it in the suite and checks the outcome.

What runs, all on loopback, on discovery ports of its own (so the fuzz reaches only the soak's
processes): the bridge (Clock and Odometry Gazebo->ROS, Twist ROS->Gazebo, a ControlWorld
service); on the Gazebo side the real Fortress peer (a 100 Hz Clock publisher stamping every
message, a 100 Hz Odometry publisher killed and restarted every 20 s, a typed Twist echo, a
ControlWorld provider); on the ROS side one rclpy process (``testing/soak_ros.py``:
subscribers, a 50 Hz Twist publisher, service calls every 0.2 s, a subscription made and
destroyed every 2 s). Every 15 s: a burst of malformed discovery datagrams, and a rogue
ZeroMQ publisher of the Odometry topic sending undecodable payloads and malformed multipart
messages. The bridge's RSS and CPU are sampled every 2 s.
"""

from __future__ import annotations

import json
import random
import signal
import socket
import sys
import threading
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import zmq

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport.api import Scope
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.zmq.wire import (
    DiscoveryMessage,
    DiscoveryType,
    MessagePublisher,
    PublisherRecord,
    encode_discovery,
)
from testing.e2e_harness import PARAMETER_BRIDGE, ProcessGroup, lines
from testing.gzpeer import PeerProcess, peer_binary
from testing.procstat import cpu_seconds, rss_mb
from testing.run_env import run_env

ROOT = Path(__file__).resolve().parent.parent
ROS_SIDE = Path(__file__).resolve().parent / "soak_ros.py"
CLOCK, ODOM, CMD, SERVICE = "/soak_clock", "/soak_odom", "/soak_cmd", "/soak_control"
RESTART_EVERY = 20.0
FUZZ_EVERY = 15.0
FUZZ_COUNT = 300
SAMPLE_EVERY = 2.0
ODOM_TEXT = "header { stamp { sec: 7 } } pose { position { x: 1.5 } }"


@dataclass
class Figures:
    """What one soak run measured."""

    seconds: float = 0.0
    #: (seconds since start, bridge RSS in MB, bridge CPU % since the previous sample).
    samples: list[tuple[float, float, float]] = field(default_factory=list)
    restarts: int = 0
    fuzz_datagrams: int = 0
    fuzz_frames: int = 0
    ros: dict[str, Any] = field(default_factory=dict)
    commands_at_gazebo: int = 0
    bridge_alive: bool = True
    bridge_exit: int | None = None
    status_table: str = ""


def soak_env() -> dict[str, str]:
    """run_env with discovery ports of the soak's own."""
    env = run_env()
    port = random.randrange(21000, 29000, 2)
    for prefix in ("GZ_", "IGN_"):
        env[prefix + "DISCOVERY_MSG_PORT"] = str(port)
        env[prefix + "DISCOVERY_SRV_PORT"] = str(port + 1)
    return env


class Soak:
    """One run: start everything, fault it on schedule, sample, stop, collect."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.env = soak_env()
        self.group = ProcessGroup()
        self.figures = Figures(seconds=seconds)
        self._stop = threading.Event()
        self._peer = str(peer_binary())
        self._odom: PeerProcess | None = None

    def run(self) -> Figures:
        try:
            self._start()
            self._loop()
            self._finish()
        finally:
            self._stop.set()
            self.group.stop()
        return self.figures

    def _start(self) -> None:
        clock_file = ROOT / ".build" / f"soak-clock-{uuid.uuid4().hex[:6]}.pb"
        clock_file.parent.mkdir(exist_ok=True)
        clock_file.write_bytes(message_class("gz.msgs.Clock")().SerializeToString())
        lifetime = str(int(self.seconds) + 60)
        self.bridge = self.group.start(
            [
                str(PARAMETER_BRIDGE),
                f"{CLOCK}@rosgraph_msgs/msg/Clock[gz.msgs.Clock",
                f"{ODOM}@nav_msgs/msg/Odometry[gz.msgs.Odometry",
                f"{CMD}@geometry_msgs/msg/Twist]gz.msgs.Twist",
                f"{SERVICE}@ros_gz_interfaces/srv/ControlWorld",
                "--ros-args", "-p", "service_timeout:=1.0",
            ],
            self.env,
        )  # fmt: skip
        self._gazebo([
            "kind-pub", CLOCK, "ignition.msgs.Clock", str(clock_file), lifetime,
            "--stamp", "sim", "--hz", "100", "--wait", "60",
        ])  # fmt: skip
        self.echo = self._gazebo(["echo", CMD, "ignition.msgs.Twist", lifetime, "--sha"])
        self._gazebo(
            ["reply", SERVICE, "ignition.msgs.WorldControl", "ignition.msgs.Boolean", lifetime]
        )
        self._restart_odom()
        spec = {
            "clock": CLOCK,
            "odom": ODOM,
            "cmd": CMD,
            "service": SERVICE,
            "seconds": self.seconds + 30,
        }
        self.ros = self.group.start([sys.executable, str(ROS_SIDE), json.dumps(spec)], self.env)
        self.figures.restarts = 0

    def _gazebo(self, args: list[str]) -> PeerProcess:
        return self.group.start([self._peer, *args], self.env)

    def _restart_odom(self) -> None:
        if self._odom is not None:
            self._odom.send_signal(signal.SIGKILL)
            self._odom.wait(5)
            self.figures.restarts += 1
        self._odom = self._gazebo(
            ["pub", ODOM, "ignition.msgs.Odometry", "100", "0", ODOM_TEXT, "--wait", "0"]
        )

    def _loop(self) -> None:
        start = time.monotonic()
        next_restart = start + RESTART_EVERY
        next_fuzz = start + FUZZ_EVERY / 2
        next_sample = start
        last_cpu, last_time = cpu_seconds(self.bridge.pid), start
        while (now := time.monotonic()) < start + self.seconds:
            if self.bridge.poll() is not None:
                self.figures.bridge_alive = False
                return
            if now >= next_restart:
                self._restart_odom()
                next_restart += RESTART_EVERY
            if now >= next_fuzz:
                self._fuzz()
                next_fuzz += FUZZ_EVERY
            if now >= next_sample:
                cpu = cpu_seconds(self.bridge.pid)
                percent = 100 * (cpu - last_cpu) / max(now - last_time, 1e-6)
                self.figures.samples.append(
                    (round(now - start, 1), rss_mb(self.bridge.pid), round(percent, 1))
                )
                last_cpu, last_time = cpu, now
                next_sample += SAMPLE_EVERY
            time.sleep(0.1)

    def _finish(self) -> None:
        # The ROS side stops publishing and prints its final counts; the commands still on
        # their way then reach Gazebo, so both ends count the same commands.
        self.ros.stop(grace=5.0)
        time.sleep(0.5)
        stats = lines(self.ros, "STATS ")
        self.figures.ros = json.loads(stats[-1]) if stats else {}
        self.figures.commands_at_gazebo = len(lines(self.echo, "MSG "))
        if self.figures.bridge_alive:
            self.bridge.send_signal(signal.SIGUSR1)
            time.sleep(1.0)
            output = self.bridge.output().splitlines()
            heads = [i for i, line in enumerate(output) if line.startswith("LEVEL ")]
            self.figures.status_table = "\n".join(output[heads[-1] :]) if heads else ""
            self.bridge.send_signal(signal.SIGTERM)
            self.figures.bridge_exit = self.bridge.wait(10)

    # --- faults ---------------------------------------------------------------------------

    def _fuzz(self) -> None:
        self.figures.fuzz_datagrams += fuzz_discovery(self.env, FUZZ_COUNT)
        self.figures.fuzz_frames += rogue_publisher(self.env, FUZZ_COUNT, self._stop)


def fuzz_discovery(env: dict[str, str], count: int) -> int:
    """``count`` malformed or mutated discovery datagrams to the soak's group and port."""
    port = int(env["GZ_DISCOVERY_MSG_PORT"])
    valid = encode_discovery(DiscoveryMessage(DiscoveryType.HEARTBEAT, str(uuid.uuid4())))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        for index in range(count):
            if index % 3 == 0:
                data = random.randbytes(random.randrange(1, 300))
            else:
                mutated = bytearray(valid)
                mutated[random.randrange(len(mutated))] ^= 1 << random.randrange(8)
                data = bytes(mutated)
            sock.sendto(data, ("239.255.0.7", port))
    return count


def rogue_publisher(env: dict[str, str], count: int, stop: threading.Event) -> int:
    """A ZeroMQ publisher of the odometry topic that sends garbage: ``count`` undecodable
    payloads and ``count`` malformed multipart messages. Returns how many were sent."""
    context = zmq.Context()
    pub = context.socket(zmq.PUB)
    pub.setsockopt(zmq.LINGER, 0)
    pub.bind("tcp://127.0.0.1:*")
    address = pub.getsockopt_string(zmq.LAST_ENDPOINT)
    process = str(uuid.uuid4())
    fqn = fully_qualified_name(env["GZ_PARTITION"], "", ODOM)
    record = PublisherRecord(
        fqn,
        address,
        process,
        str(uuid.uuid4()),
        Scope.ALL,
        MessagePublisher("ignition.msgs.Odometry"),
    )
    port = int(env["GZ_DISCOVERY_MSG_PORT"])
    sent = 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        for _ in range(3):  # announce, and give subscribers time to connect and register
            for kind in (DiscoveryType.HEARTBEAT, DiscoveryType.ADVERTISE):
                message = DiscoveryMessage(
                    kind, process, pub=record if kind == DiscoveryType.ADVERTISE else None
                )
                udp.sendto(encode_discovery(message), ("239.255.0.7", port))
            time.sleep(0.5)
        for index in range(count):
            if stop.is_set():
                break
            garbage = random.randbytes(random.randrange(1, 64)) + b"\xff\xff"
            pub.send_multipart([fqn.encode(), address.encode(), garbage, b"ignition.msgs.Odometry"])
            frames = [fqn.encode()] + [b"x"] * (2 if index % 2 else 4)
            pub.send_multipart(frames)
            sent += 2
            time.sleep(0.001)
        bye = DiscoveryMessage(DiscoveryType.UNADVERTISE, process, pub=record)
        udp.sendto(encode_discovery(bye), ("239.255.0.7", port))
    context.destroy(linger=0)
    return sent
