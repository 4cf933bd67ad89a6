"""Start-up (issue 23): from the bridge process's start to its first and last ``Creating`` line.

Usage: ``.venv/bin/python -m benchmarks.startup [--counts 1 3 8 66] [--rounds 5] [--hz 100]``.

Per count N: ``parameter_bridge`` with N inline entries ``/t<i>@std_msgs/msg/String@
gz.msgs.StringMsg`` (both directions, as in the issue), started ``--rounds`` times without
traffic, then as often while the C++ peer on Ignition Transport 11 (``testing/peer``, mode
pub-many: one process, one node, as upstream ros_gz_bridge's ``test_gz_publisher``) already
publishes on every one of those Gazebo topics at ``--hz``. The
times come from the bridge's own log (``{time}`` of rcutils, wall clock) minus the wall clock
just before the process was started: imports, rclpy init, node, settings, Gazebo discovery
start and the channels. Beside them, the floor of any rclpy process: a script that imports
rclpy, makes a node and one String publisher and logs one line, timed the same way. The
bridge's modules are byte-compiled first (this environment sets PYTHONDONTWRITEBYTECODE, and an
installed package has its bytecode).
"""

from __future__ import annotations

import argparse
import compileall
import os
import re
import statistics
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from benchmarks.harness import BIN, ROOT, topic_name
from benchmarks.report import write_section
from testing.gzpeer import start_peer, stop_processes, wait_for_line
from testing.run_env import run_env

#: What the issue measured for the C++ bridge (three inline entries, last ``Creating`` line).
QUOTED_CPP_S = 0.15
#: Issue 22: with traffic flowing, the last channel exists within this long of the first.
GOAL_SPAN_S = 1.0
#: The bridge's log lines with rcutils' wall-clock time first.
LOG_FORMAT = "{time} {message}"
CREATING = re.compile(r"^(\d+\.\d+) Creating ")
#: The environment that makes a bridge print its ``Creating`` lines in that format.
LOG_ENV = {
    "RCUTILS_LOGGING_SEVERITY_THRESHOLD": "INFO",
    "RCUTILS_CONSOLE_OUTPUT_FORMAT": LOG_FORMAT,
}
#: A process that only does what every rclpy node must before it publishes; ``{node}`` is
#: rclpy's node, or one whose own services are held back as the bridge's are.
FLOOR_SCRIPT = (
    "import rclpy\n"
    "from rclpy.node import Node\n"
    "from rclpy.parameter import Parameter\n"
    "from std_msgs.msg import String\n"
    "rclpy.init()\n"
    "node = {node}\n"
    "node.create_publisher(String, '/startup_floor', 10)\n"
    "node.get_logger().info('Creating a publisher')\n"
)
PLAIN_NODE = "Node('startup_floor')"
HELD_NODE = (
    "Node('startup_floor', start_parameter_services=False, parameter_overrides="
    "[Parameter('start_type_description_service', value=False)])"
)
#: Fast DDS without the executables' profile (its 64 MB shared-memory segment).
PROFILE_OFF = {"ROS_GZ_BRIDGE_FASTDDS_PROFILE": "off"}
#: Issue 23: entries of the C++ figure (its last ``Creating`` line).
QUOTED_CPP_ENTRIES = 3
TIMEOUT = 60.0


@dataclass(frozen=True)
class Row:
    label: str
    first_s: tuple[float, ...]
    last_s: tuple[float, ...]


def creating_times(
    command: Sequence[str], count: int, extra_env: Mapping[str, str] | None = None
) -> tuple[float, float]:
    """Seconds from the start of ``command`` to its first and its ``count``-th ``Creating``
    line; the process is then stopped. ``extra_env`` is applied before the Fast DDS profile
    is chosen."""
    env = run_env(base={**os.environ, **(extra_env or {})}) | LOG_ENV
    started = time.time()
    proc = subprocess.Popen(
        list(command), env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    assert proc.stdout is not None
    stamps: list[float] = []
    deadline = time.monotonic() + TIMEOUT
    try:
        for line in proc.stdout:
            if match := CREATING.match(line):
                stamps.append(float(match.group(1)) - started)
                if len(stamps) == count:
                    return stamps[0], stamps[-1]
            if time.monotonic() > deadline:
                break
        msg = f"{len(stamps)} of {count} Creating lines from {command[0]}"
        raise RuntimeError(msg)
    finally:
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def bridge_rounds(
    count: int,
    rounds: int,
    hz: float | None,
    *,
    spread: bool = False,
    extra_env: Mapping[str, str] | None = None,
    note: str = "",
) -> Row:
    """``rounds`` start-ups of a bridge of ``count`` entries; with ``hz``, while the C++ peer
    publishes on each of its Gazebo topics, from one process, or with ``spread`` from one
    process per topic (a heavier machine: every process has its threads and answers every
    discovery datagram). ``extra_env``: the bridge's environment beside the benchmark's,
    ``note`` says so in the row's label."""
    topics = [topic_name(f"startup{count}_{i}") for i in range(count)]
    command = [str(BIN / "parameter_bridge")]
    command += [f"{topic}@std_msgs/msg/String@gz.msgs.StringMsg" for topic in topics]
    try:
        if hz is not None:
            publish = ["ignition.msgs.StringMsg", str(hz), 'data: "flowing"']
            groups = [[topic] for topic in topics] if spread else [topics]
            peers = [start_peer("pub-many", *publish, *group, env=run_env()) for group in groups]
            for peer in peers:
                wait_for_line(peer, "^READY", timeout=30)
            time.sleep(1.0)  # flowing before the bridge starts
        times = [creating_times(command, 2 * count, extra_env) for _ in range(rounds)]
    finally:
        stop_processes()
    label = f"{count} {'entry' if count == 1 else 'entries'}"
    if hz is None:
        label += ", no traffic"
    else:
        label += f", {count} Gazebo topic{'' if count == 1 else 's'} at {hz:g} Hz"
        label += f" from {count} processes" if spread else " from one process"
    return Row(label + note, tuple(t[0] for t in times), tuple(t[1] for t in times))


def floor_rounds(
    rounds: int, node: str, label: str, extra_env: Mapping[str, str] | None = None
) -> Row:
    command = [sys.executable, "-c", FLOOR_SCRIPT.format(node=node)]
    times = [creating_times(command, 1, extra_env) for _ in range(rounds)]
    return Row(label, tuple(t[0] for t in times), ())


def floor_rows(rounds: int) -> list[Row]:
    """The rclpy floor: rclpy's node, one whose services are held back as the bridge's are,
    and that one without the Fast DDS profile."""
    return [
        floor_rounds(rounds, PLAIN_NODE, "rclpy floor: a node and one publisher"),
        floor_rounds(rounds, HELD_NODE, "rclpy floor, the node's services held back"),
        floor_rounds(rounds, HELD_NODE, "the same, Fast DDS profile off", extra_env=PROFILE_OFF),
    ]


def _spans(row: Row) -> tuple[float, ...]:
    return tuple(last - first for first, last in zip(row.first_s, row.last_s, strict=False))


def goal_line(rows: Sequence[Row], hz: float) -> str:
    """Issue 22's start-up goal, judged on the row of the most entries with traffic."""
    busy = [row for row in rows if "one process" in row.label and row.last_s]
    if not busy:
        return "- not measured"
    row = busy[-1]
    span = statistics.median(_spans(row))
    met = span < GOAL_SPAN_S
    return (
        f"- Issue 22: with {row.label.split(',')[0]} and traffic already flowing ({hz:g} Hz a "
        f"topic), the last channel exists within {GOAL_SPAN_S:g} s of the first: "
        f"{span:.3f} s (median) — "
        + ("**met**" if met else f"**missed** by {span - GOAL_SPAN_S:.3f} s")
    )


def cpp_line(rows: Sequence[Row]) -> str:
    """Issue 23's start-up goal: the last ``Creating`` line of the C++ figure's entries."""
    lines = []
    for row in rows:
        if row.label.startswith(f"{QUOTED_CPP_ENTRIES} entries, no traffic"):
            last = statistics.median(row.last_s)
            verdict = (
                "**met**" if last <= QUOTED_CPP_S else f"**missed**, {last / QUOTED_CPP_S:.1f}x"
            )
            lines.append(
                f"- Issue 23: {row.label}, the last channel {last:.3f} s after start (median); "
                f"the C++ bridge {QUOTED_CPP_S:g} s — {verdict}"
            )
    return "\n".join(lines) or "- Issue 23: not measured"


def _cell(values: tuple[float, ...]) -> str:
    if not values:
        return "-"
    return f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})"


def report(rows: Sequence[Row], args: argparse.Namespace, load: float) -> str:
    lines = [
        "## Start-up (issue 23)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.startup --counts "
        f"{' '.join(map(str, args.counts))} --rounds {args.rounds} --hz {args.hz:g}`",
        "",
        "Seconds from the start of the `parameter_bridge` process to its first and its last "
        "`Creating` line (median of the rounds, range in brackets). N inline entries "
        "`/t<i>@std_msgs/msg/String@gz.msgs.StringMsg`, both directions, so 2N lines. "
        "*With traffic*: the C++ peer on Ignition Transport 11 (mode `pub-many`: one process, "
        "one node, as upstream ros_gz_bridge's `test_gz_publisher`) publishes on every Gazebo "
        "topic from 1 s before the bridge starts; the last row spreads the topics over one process "
        "each, a heavier machine (every process has its threads and answers every discovery "
        "datagram). The rclpy floor is "
        "a script that only imports rclpy, makes a node and one publisher and logs: what any "
        "rclpy process spends first; then the same with the node's parameter and type "
        "description services held back, as the bridge holds them until its channels exist "
        "(creating a service imports numpy); then that without the executables' Fast DDS "
        "profile, whose 64 MB shared-memory segment Fast DDS allocates and clears when the "
        "participant is made (the bridge applies it; `ROS_GZ_BRIDGE_FASTDDS_PROFILE=off` in "
        "the profile-off rows). "
        f"The C++ bridge: {QUOTED_CPP_S:g} s to its last line with {QUOTED_CPP_ENTRIES} "
        "entries (quoted from issue 23, measured elsewhere, with Fast DDS's built-in profile). "
        "Bytecode compiled beforehand. "
        f"1-minute load average before the run: {load:.2f} (the machine, 2 cores, is shared).",
        "",
        "| bridge | first `Creating` s | last `Creating` s | last - first s |",
        "|---|---|---|---|",
    ]
    lines += [
        f"| {row.label} | {_cell(row.first_s)} | {_cell(row.last_s)} | {_cell(_spans(row))} |"
        for row in rows
    ]
    lines += ["", cpp_line(rows), goal_line(rows, args.hz)]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 3, 8, 66])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--hz", type=float, default=100.0)
    args = parser.parse_args(argv)
    compileall.compile_dir(ROOT / "ros_gz_bridge_py", quiet=1)
    load = os.getloadavg()[0]
    rows = floor_rows(args.rounds)
    for hz in (None, args.hz):
        for count in args.counts:
            print(f"== {count} entries, hz {hz}", file=sys.stderr, flush=True)
            rows.append(bridge_rounds(count, args.rounds, hz))
            print(rows[-1], file=sys.stderr, flush=True)
        if hz is None and QUOTED_CPP_ENTRIES in args.counts:
            off = ", Fast DDS profile off"
            rows.append(
                bridge_rounds(
                    QUOTED_CPP_ENTRIES, args.rounds, None, extra_env=PROFILE_OFF, note=off
                )
            )
    rows.append(bridge_rounds(max(args.counts), args.rounds, args.hz, spread=True))
    write_section("startup", report(rows, args, load))
    return 0


if __name__ == "__main__":
    sys.exit(main())
