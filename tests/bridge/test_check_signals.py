"""SIGINT and SIGTERM end ``parameter_bridge --check`` and ``--discover`` while they listen, as
they end a bridge: promptly, exit status 0, no traceback; and neither listens forever."""

from __future__ import annotations

import signal
import subprocess

import pytest

from ros_gz_bridge_py.app.check import STOPPED
from testing.behaviour_harness import STRING, WAIT, bridge_command, started
from testing.gzpeer import PeerProcess, start_process, unique_name, wait_for_line

__all__ = ["started"]

pytestmark = [pytest.mark.ros]

#: As tests/bridge/test_behaviour_signals.py: the bound for an exit after the signal.
EXIT_WITHIN = 2.0
#: Far longer than the test: only the signal can end the listening in time.
SECONDS = "60"
#: What each mode prints once it listens, and what it leaves after the signal.
MODES = {
    "--check": (rf"^Listening for {SECONDS} s: Gazebo", STOPPED),
    "--discover": (
        rf"Listening to Gazebo discovery for {SECONDS} s",
        f"# Written by parameter_bridge --discover {SECONDS}: ",
    ),
}


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("mode", sorted(MODES))
def test_a_signal_ends_the_listening_at_once(
    mode: str, signum: signal.Signals, started: list[PeerProcess]
) -> None:
    listening, left = MODES[mode]
    topic = unique_name("check_signal")
    process = start_process(bridge_command(mode, SECONDS, f"{topic}@std_msgs/msg/String]{STRING}"))
    started.append(process)
    wait_for_line(process, listening, timeout=30)

    process.send_signal(signum)
    try:
        status = process.wait(EXIT_WITHIN)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running {EXIT_WITHIN} s after {signum.name}:\n{process.output()}")

    assert status == 0, process.output()
    assert left in process.output()
    assert "Traceback" not in process.output()


@pytest.mark.parametrize("mode", sorted(MODES))
def test_listening_forever_is_refused(mode: str) -> None:
    done = subprocess.run(
        bridge_command(mode, "inf", f"/a@std_msgs/msg/String@{STRING}"),
        capture_output=True, text=True, timeout=WAIT * 3, check=False,
    )  # fmt: skip
    assert done.returncode == 255
    assert done.stderr.strip() == (
        f"parameter_bridge: argument '{mode} inf': {mode} takes a number of seconds > 0 to "
        "listen for (finite), not 'inf'"
    )
