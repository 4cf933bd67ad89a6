"""The native data plane against real peers, and the bridge without it (docs/native.md §1).

A Fortress C++ peer publishes Odometry, JointState (a Model) and a Clock; a ``parameter_bridge``
carries them to an rclpy checker process, which also publishes a Twist that the bridge carries
to a Fortress subscriber (``cmd_vel``, as DiffDrive takes it). The same run is made with the
native path (where the extension is built), with ``ROS_GZ_BRIDGE_NATIVE=off``, and with the
extension absent (an import blocker in the bridge process's ``sitecustomize``): the values must
arrive alike, the SIGUSR1 table must name the path each channel took, and a bridge without the
extension says once why. The core tests also run in a process where the extension cannot be
imported.
"""

from __future__ import annotations

import functools
import os
import re
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ros_gz_bridge_py.app.settings import NATIVE_ENV, switched_off
from ros_gz_bridge_py.native import extension
from testing.e2e_harness import (
    RUN_TIMEOUT,
    GzEcho,
    ProcessGroup,
    RosChecker,
    parse_gz,
    wait_all,
)
from testing.gzpeer import ROOT, unique_name, wait_for_line
from tests.bridge.e2e_values import (
    CLOCK,
    JOINT_STATES,
    ODOMETRY,
    TWIST_TO_GZ,
    GzSample,
    mismatches,
)

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

#: (ROS type, sample) of each channel.
CHANNELS = (
    ("nav_msgs/msg/Odometry", ODOMETRY),
    ("sensor_msgs/msg/JointState", JOINT_STATES),
    ("rosgraph_msgs/msg/Clock", CLOCK),
)
#: Makes ``import ros_gz_bridge_py.native._native`` fail, as where the extension is not built.
BLOCKER = """\
import importlib.abc
import sys


class _NoNativeExtension(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == "ros_gz_bridge_py.native._native":
            raise ImportError("blocked by the test: no native extension")
        return None


sys.meta_path.insert(0, _NoNativeExtension())
"""
WHY_NOT_BUILT = "Every channel takes the Python path: the native extension is not built"


def require_native() -> None:
    """The native checks need a bridge that takes the native path: skipped under
    ``ROS_GZ_BRIDGE_NATIVE=off`` (under which the suite also runs; the bridge inherits it). The
    native extension must be built where tests run in CI (the fresh machine has a compiler and
    Python headers); elsewhere its absence skips them too."""
    if switched_off(NATIVE_ENV, os.environ):
        pytest.skip(f"{NATIVE_ENV}=off: every channel takes the Python path")
    if extension() is not None:
        return
    if os.environ.get("CI") == "true":
        pytest.fail("the native extension is not built (pip install -e . builds it)")
    pytest.skip("the native extension is not built")


def blocker_env(tmp: Path) -> dict[str, str]:
    """Our environment, with the extension made unimportable in the processes it starts, and
    without ``ROS_GZ_BRIDGE_NATIVE`` (with it off, a bridge names the switch as its reason
    instead of the missing extension)."""
    folder = tmp / "no_native"
    folder.mkdir(exist_ok=True)
    (folder / "sitecustomize.py").write_text(BLOCKER)
    path = os.environ.get("PYTHONPATH", "")
    env = {key: value for key, value in os.environ.items() if key != NATIVE_ENV}
    return {**env, "PYTHONPATH": f"{folder}{os.pathsep}{path}" if path else str(folder)}


class Run:
    """A bridge carrying the three channels from the Fortress peer to the rclpy checker."""

    def __init__(self, group: ProcessGroup, env: dict[str, str] | None) -> None:
        self.topics = {
            sample.type_name: unique_name(f"native_{sample.type_name}") for _, sample in CHANNELS
        }
        self.cmd_vel = unique_name("native_cmd_vel")
        arguments = [
            f"{self.topics[sample.type_name]}@{ros_type}[{sample.gz_type}"
            for ros_type, sample in CHANNELS
        ]
        arguments.append(f"{self.cmd_vel}@{TWIST_TO_GZ.ros_type}]gz.msgs.Twist")
        self.bridge = group.bridge(*arguments, env=env)
        for _, sample in CHANNELS:
            group.peer(*sample.peer_pub_args(self.topics[sample.type_name]))
        self.echo = GzEcho.peer(group, self.cmd_vel, "Twist", "ignition.msgs.Twist")
        self.checker = RosChecker(
            group,
            [(self.topics[sample.type_name], ros_type) for ros_type, sample in CHANNELS],
            [(self.cmd_vel, TWIST_TO_GZ.ros_type, TWIST_TO_GZ.values)],
        )

    def arrived(self, sample: GzSample) -> bool:
        messages = self.checker.messages(self.topics[sample.type_name])
        return any(not mismatches(sample.ros, message) for message in messages)

    def twist_arrived(self) -> bool:
        return parse_gz("Twist", TWIST_TO_GZ.gz_text) in self.echo.messages()

    def wait_for_values(self) -> None:
        checks: dict[str, Callable[[], bool]] = {"cmd_vel": self.twist_arrived}
        checks |= {
            sample.type_name: functools.partial(self.arrived, sample) for _, sample in CHANNELS
        }
        held = wait_all(checks, RUN_TIMEOUT)
        assert all(held.values()), f"{held}; bridge output:\n{self.bridge.output()[-3000:]}"

    def paths(self) -> dict[str, str]:
        """The PATH column of each channel's row in the SIGUSR1 table."""
        self.bridge.send_signal(signal.SIGUSR1)
        found = {}
        rows = [("GZ->ROS", self.topics[sample.type_name]) for _, sample in CHANNELS]
        rows.append(("ROS->GZ", self.cmd_vel))
        for direction, topic in rows:
            row = rf"^\w+\s+{direction}\s+{re.escape(topic)}\s.*\s(native|python)$"
            found[topic] = wait_for_line(self.bridge, row).group(1)
        return found

    def all_paths(self, path: str) -> dict[str, str]:
        return dict.fromkeys([*self.topics.values(), self.cmd_vel], path)


@pytest.fixture
def group() -> Iterator[ProcessGroup]:
    processes = ProcessGroup()
    yield processes
    processes.stop()


def test_the_native_path_carries_fortress_messages_with_their_values(group: ProcessGroup) -> None:
    require_native()
    run = Run(group, None)
    run.wait_for_values()
    assert run.paths() == run.all_paths("native")
    assert "Every channel takes the Python path" not in run.bridge.output()


def test_native_off_keeps_the_python_path_with_the_same_values(group: ProcessGroup) -> None:
    run = Run(group, {**os.environ, NATIVE_ENV: "off"})
    run.wait_for_values()
    assert run.paths() == run.all_paths("python")


def test_without_the_extension_the_bridge_says_why_once_and_works(
    group: ProcessGroup, tmp_path: Path
) -> None:
    run = Run(group, blocker_env(tmp_path))
    run.wait_for_values()
    assert run.paths() == run.all_paths("python")
    assert run.bridge.output().count(WHY_NOT_BUILT) == 1, run.bridge.output()


def test_the_core_tests_pass_without_the_extension(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", "tests/core"],
        cwd=ROOT,
        env=blocker_env(tmp_path),
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert " passed" in result.stdout
