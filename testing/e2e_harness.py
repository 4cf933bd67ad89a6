"""Processes of the end-to-end bridge tests: the bridge, the rclpy checker, Gazebo echoes.

Every process is a :class:`testing.gzpeer.PeerProcess` owned by a :class:`ProcessGroup`, which
stops them together. They are not registered with ``testing.gzpeer.stop_processes``: a run is
shared by the tests of a module, and another test's per-test clean-up must not end it.
Output is parsed from the lines collected so far, so checks can poll without consuming.
"""

from __future__ import annotations

import contextlib
import json
import signal
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from google.protobuf import text_format

from ros_gz_bridge_py.msgs import message_class
from testing.gzpeer import PeerProcess, peer_binary

#: The console script of the venv running the tests (``pip install -e .`` put it next to the
#: interpreter; a worktree or a copy of the checkout has no ``.venv`` of its own).
PARAMETER_BRIDGE = Path(sys.prefix) / "bin" / "parameter_bridge"
CHECKER = Path(__file__).resolve().parent / "e2e_ros_checker.py"
#: Upper bound for one run to see every expected message (2 shared cores, many processes).
RUN_TIMEOUT = 60.0


class ProcessGroup:
    """Processes started for one run, stopped together."""

    def __init__(self) -> None:
        self._started: list[PeerProcess] = []

    def start(self, command: Sequence[str], env: Mapping[str, str] | None = None) -> PeerProcess:
        """Start ``command`` (inheriting our environment unless ``env`` is given)."""
        proc = PeerProcess(command, env)
        self._started.append(proc)
        return proc

    def bridge(self, *args: str, env: Mapping[str, str] | None = None) -> PeerProcess:
        """``parameter_bridge ARGS``."""
        return self.start([str(PARAMETER_BRIDGE), *args], env)

    def peer(self, *args: str) -> PeerProcess:
        """The C++ ign-transport 11 peer."""
        return self.start([str(peer_binary()), *args])

    def python(self, script: Path, *args: str, env: Mapping[str, str] | None = None) -> PeerProcess:
        """A Python script of ours, run by this interpreter."""
        return self.start([sys.executable, str(script), *args], env)

    def stop(self) -> None:
        """SIGTERM to all at once, then each gets the grace period of ``PeerProcess.stop``."""
        for proc in self._started:
            if proc.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    proc.send_signal(signal.SIGTERM)
        while self._started:
            self._started.pop().stop()


def lines(proc: PeerProcess, prefix: str) -> list[str]:
    """The rest of every output line so far that starts with ``prefix``."""
    return [line[len(prefix) :] for line in proc.output().splitlines() if line.startswith(prefix)]


class RosChecker:
    """The rclpy checker process (``e2e_ros_checker.py``)."""

    def __init__(
        self,
        group: ProcessGroup,
        subscribe: Sequence[tuple[str, str]],
        publish: Sequence[tuple[str, str, dict[str, Any]]] = (),
        seconds: float = RUN_TIMEOUT + 30,
    ) -> None:
        spec = {
            "subscribe": [list(item) for item in subscribe],
            "publish": [list(item) for item in publish],
            "seconds": seconds,
        }
        self.proc = group.python(CHECKER, json.dumps(spec))

    def messages(self, topic: str) -> list[dict[str, Any]]:
        """The distinct messages received on ``topic`` so far."""
        records = (json.loads(text) for text in lines(self.proc, "MSG "))
        return [record["msg"] for record in records if record["topic"] == topic]

    def matched(self, topic: str) -> bool:
        """Whether the checker's publisher on ``topic`` has seen another subscriber."""
        return topic in lines(self.proc, "MATCHED ")


class GzEcho:
    """A Gazebo echo process printing ``MSG <type> <text>`` lines, decoded with gz-msgs 10."""

    def __init__(self, proc: PeerProcess, type_name: str) -> None:
        self.proc = proc
        self.type_name = type_name

    @classmethod
    def peer(cls, group: ProcessGroup, topic: str, type_name: str, wire_type: str) -> GzEcho:
        """``ign_peer echo`` of ``topic``, subscribed as ``wire_type``."""
        args = ["echo", topic, f"ignition.msgs.{type_name}", str(RUN_TIMEOUT + 30)]
        if wire_type != f"ignition.msgs.{type_name}":
            args += ["--wire-type", wire_type]
        return cls(group.peer(*args), type_name)

    def messages(self) -> list[Any]:
        """Every message received so far (text format parsed as ``gz.msgs.<type>``)."""
        found = []
        for record in lines(self.proc, "MSG "):
            _wire_type, _, text = record.partition(" ")
            found.append(parse_gz(self.type_name, text))
        return found


def status_rows(bridge: PeerProcess, topics: Sequence[str]) -> list[str]:
    """The rows (and explanations) of the bridge's status table that name ``topics``, after
    the table's header: the bridge prints the table on SIGUSR1, which this sends."""
    bridge.send_signal(signal.SIGUSR1)
    time.sleep(1.0)
    table = bridge.output().splitlines()
    header = [line for line in table if "LIMITED" in line][-1:]
    named = [
        line for line in table if any(f"{topic}{end}" in line for topic in topics for end in " :")
    ]
    return header + named


def parse_gz(type_name: str, text: str) -> Any:
    """Protobuf text of a ``<type_name>`` message as a gz-msgs 10 message."""
    return text_format.Parse(text, message_class(f"gz.msgs.{type_name}")())


def wait_all(checks: Mapping[str, Callable[[], bool]], timeout: float) -> dict[str, bool]:
    """Poll every check until all hold or ``timeout`` passes; which ones held."""
    deadline = time.monotonic() + timeout
    held = dict.fromkeys(checks, False)
    while True:
        for name, check in checks.items():
            held[name] = held[name] or check()
        if all(held.values()) or time.monotonic() > deadline:
            return held
        time.sleep(0.1)


@dataclass(frozen=True)
class ConfigEntry:
    """One topic entry of a bridge YAML file, names as the bridge node in ``/`` resolves them."""

    ros_topic: str
    gz_topic: str
    ros_type: str
    gz_type: str
    direction: str


def read_entries(path: Path) -> list[ConfigEntry]:
    """The topic entries of a YAML configuration."""
    entries = []
    for item in yaml.safe_load(path.read_text()):
        ros_topic = item.get("ros_topic_name", item.get("topic_name"))
        entries.append(
            ConfigEntry(
                ros_topic=ros_topic if ros_topic.startswith("/") else f"/{ros_topic}",
                gz_topic=item.get("gz_topic_name", item.get("topic_name")),
                ros_type=item["ros_type_name"],
                gz_type=item["gz_type_name"],
                direction=item.get("direction", "BIDIRECTIONAL"),
            )
        )
    return entries
