"""SIGINT and SIGTERM stop ``parameter_bridge`` cleanly.

Clean means: exit status 0 promptly, no traceback, nothing of the process left (its whole
process group is gone), and the Gazebo side told that the bridge's topic is gone (an
unadvertisement, not a peer that went silent and expired).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
import uuid

import pytest
from rcl_interfaces.srv import ListParameters
from ros_gz_interfaces.srv import ControlWorld

from ros_gz_bridge_py.transport import GzNode
from ros_gz_bridge_py.transport.zmq.discovery import SILENCE_INTERVAL
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_advertised,
    gz_node,
    ros_side,
    start_bridge,
    started,
    wait_gz_advertised,
)
from testing.e2e_harness import PARAMETER_BRIDGE
from testing.gzpeer import PeerProcess, require_peer, unique_name, wait_for_line, wait_until

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

#: The brief's bound for a clean exit after the signal.
EXIT_WITHIN = 2.0


def wait_until_spinning(ros_side: RosSide, node_name: str) -> None:
    """Wait until the bridge's executor answers its parameter service.

    The bridge installs its signal handlers just before it starts spinning; a signal during
    start-up is another case (see the report).
    """
    client = ros_side.run(
        lambda: ros_side.node.create_client(ListParameters, f"/{node_name}/list_parameters")
    )
    try:
        deadline = time.monotonic() + WAIT
        future = None
        while future is None or not future.done():
            if time.monotonic() > deadline:
                pytest.fail(f"{node_name} never answered list_parameters")
            if future is None and client.service_is_ready():
                future = ros_side.run(lambda: client.call_async(ListParameters.Request()))
            time.sleep(0.02)
    finally:
        ros_side.destroy(client)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_the_bridge_cleanly(
    signum: signal.Signals, gz_node: GzNode, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    topic = unique_name("signal")
    node_name = f"signal_bridge_{uuid.uuid4().hex[:8]}"
    bridge = start_bridge(
        f"{topic}@std_msgs/msg/String]{STRING}",
        f"{unique_name('signal_in')}@std_msgs/msg/String[{STRING}",
        f"{unique_name('signal_svc')}@ros_gz_interfaces/srv/ControlWorld",
        ros_args=["-r", f"__node:={node_name}"],
        creating=3,
    )
    started.append(bridge)
    wait_gz_advertised(gz_node, topic)
    wait_until_spinning(ros_side, node_name)

    bridge.send_signal(signum)
    try:
        status = bridge.wait(EXIT_WITHIN)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running {EXIT_WITHIN} s after {signum.name}:\n{bridge.output()}")

    assert status == 0, bridge.output()
    assert "Traceback" not in bridge.output()
    with pytest.raises(ProcessLookupError):
        os.killpg(bridge.pid, 0)  # the session the bridge led has no process left
    # A peer that just went silent is forgotten only SILENCE_INTERVAL after its last heartbeat
    # (heartbeats come every second until the exit), so disappearing sooner than
    # SILENCE_INTERVAL - 1 s after the exit means the bridge unadvertised.
    wait_until(
        lambda: not gz_advertised(gz_node, topic), SILENCE_INTERVAL - 1.5, f"{topic} unadvertised"
    )


def test_a_call_waiting_for_gazebo_is_answered_when_the_bridge_stops(
    ros_side: RosSide, started: list[PeerProcess]
) -> None:
    """Ctrl-C while a service call waits for a Gazebo that never answers: the caller gets
    success=false at once, not silence, and the bridge exits cleanly (it printed a traceback
    from the reply callback that ran after its executor was gone)."""
    service = unique_name("signal_waiting")
    bridge = start_bridge(
        f"{service}@ros_gz_interfaces/srv/ControlWorld",
        ros_args=["-p", "service_timeout:=30.0"],
        creating=1,
    )
    started.append(bridge)
    client = ros_side.run(lambda: ros_side.node.create_client(ControlWorld, service))
    try:
        wait_until(client.service_is_ready, WAIT, f"the service {service}")
        future = ros_side.run(lambda: client.call_async(ControlWorld.Request()))
        waiting = re.compile(rf"^\w+\s+service\s+{re.escape(service)}\s+\S+\s+\S+\s+1\s", re.M)
        deadline = time.monotonic() + WAIT
        while not waiting.search(bridge.output()):  # the status table counts the call
            assert time.monotonic() < deadline, bridge.output()
            bridge.send_signal(signal.SIGUSR1)
            time.sleep(0.2)
        bridge.send_signal(signal.SIGINT)
        assert bridge.wait(WAIT) == 0, bridge.output()
        wait_until(future.done, WAIT, "the waiting call's answer")
        assert future.result().success is False
    finally:
        ros_side.destroy(client)
    assert "Traceback" not in bridge.output()
    assert "shutting down" in bridge.output()


@pytest.mark.parametrize("executable", ["parameter_bridge", "image_bridge"])
def test_sigusr1_never_kills_and_prints_the_table(executable: str) -> None:
    """SIGUSR1 during start-up is ignored (its default would kill); once running it prints
    the status table, for both executables."""
    topic = unique_name("usr1")
    bridged = f"{topic}@std_msgs/msg/String[{STRING}"
    argument = bridged if executable == "parameter_bridge" else topic
    process = PeerProcess([str(PARAMETER_BRIDGE.parent / executable), argument])
    try:
        # Before the interpreter reaches the entry point nothing can catch the signal.
        wait_until(lambda: _ignores_sigusr1(process.pid), WAIT, "SIGUSR1 ignored at start-up")
        deadline = time.monotonic() + 30
        while "Creating GZ->ROS" not in process.output():
            assert process.poll() is None, process.output()
            assert time.monotonic() < deadline, process.output()
            process.send_signal(signal.SIGUSR1)
            time.sleep(0.05)
        time.sleep(1.0)  # spinning, with the table handler installed
        process.send_signal(signal.SIGUSR1)
        wait_for_line(process, rf"^\w+\s+GZ->ROS\s+{re.escape(topic)}\s", timeout=WAIT)
        process.send_signal(signal.SIGTERM)
        assert process.wait(WAIT) == 0, process.output()
    finally:
        process.stop()


def _ignores_sigusr1(pid: int) -> bool:
    """Whether the process's ignored-signals mask (/proc/<pid>/status SigIgn) has SIGUSR1."""
    with open(f"/proc/{pid}/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("SigIgn:"):
                return bool(int(line.split()[1], 16) >> (signal.SIGUSR1 - 1) & 1)
    return False
