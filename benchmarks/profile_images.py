"""Where the bridge's time goes on the 1080p GZ->ROS image path (issue 5's "with a profile").

Usage: ``.venv/bin/python -m benchmarks.profile_images [--seconds S] [--sample S]``; writes the
report ``benchmarks/reports/profile.md``. It runs the images benchmark's flow "Gazebo publisher ->
parameter_bridge Image channel (ZeroMQ) -> rclpy subscriber", 1920x1080 rgb8 flat out, with the
same helpers (``benchmarks.bridged``), and while it publishes samples the bridge process with
``py-spy record --nonblocking --threads`` twice at once: every busy sample, and (``--gil``) only
the thread holding the GIL. Per-thread CPU comes from ``/proc/<pid>/task/<tid>/stat`` (thread
names from ``py-spy dump --json``); the publisher's and subscriber's CPU from
``/proc/<pid>/stat``. Loopback only: every process gets ``benchmarks.harness.run_env``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from benchmarks.bridged import backend, bridge_process, flow_through
from benchmarks.harness import BIN, Flow, FlowResult, bridge_argument, topic_name
from benchmarks.report import write_section
from testing.procstat import cpu_seconds

KIND = "image1080"
PY_SPY = BIN / "py-spy"
RATE = 100  # py-spy samples per second
_TICK = os.sysconf("SC_CLK_TCK")
_FRAME = re.compile(r"^(?P<func>.*) \((?P<file>[^()]*?)(?::\d+)?\)$")
_THREAD = re.compile(r"^thread \((?P<id>(?:0x)?[0-9A-Fa-f]+)\)(?:: (?P<name>.*))?$")


# --- /proc ------------------------------------------------------------------------------------


def task_cpu(pid: int) -> dict[int, float]:
    """CPU seconds of every thread (tid) of ``pid``."""
    times = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/stat", encoding="ascii") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        times[int(tid)] = (int(fields[11]) + int(fields[12])) / _TICK
    return times


def task_comm(pid: int, tid: int) -> str:
    try:
        with open(f"/proc/{pid}/task/{tid}/comm", encoding="utf-8") as comm:
            return comm.read().strip()
    except OSError:
        return "?"


def pids_with(needle: str) -> list[int]:
    """Processes whose command line contains ``needle`` (the flow's unique topic name)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/cmdline", "rb") as cmdline:
                words = cmdline.read().split(b"\0")
        except OSError:
            continue
        if any(needle.encode() in word for word in words):
            found.append(int(entry))
    return found


def role_of(pid: int) -> str:
    with open(f"/proc/{pid}/cmdline", "rb") as cmdline:
        words = [word.decode(errors="replace") for word in cmdline.read().split(b"\0")]
    if "kind-pub" in words:  # the C++ Gazebo publisher (benchmarks.harness.ign_worker)
        return "gz-pub"
    for role in ("gz-pub", "ros-sub"):
        if role in words:
            return role
    return "bridge" if any(word.endswith("parameter_bridge") for word in words) else "?"


# --- py-spy -----------------------------------------------------------------------------------


@dataclass
class Profile:
    """Aggregated raw (collapsed-stack) samples of one ``py-spy record``."""

    samples: int = 0
    self_time: Counter[str] = field(default_factory=Counter)
    inclusive: Counter[str] = field(default_factory=Counter)
    threads: Counter[str] = field(default_factory=Counter)


def frame_name(frame: str) -> str:
    match = _FRAME.match(frame)
    if match is None:
        return frame
    return f"{match['func']} ({Path(match['file']).name})"


def parse_raw(lines: Iterable[str], names: dict[int, str]) -> Profile:
    profile = Profile()
    for line in lines:
        stack, _, count_text = line.rstrip("\n").rpartition(" ")
        if not stack or not count_text.isdigit():
            continue
        count = int(count_text)
        frames = stack.split(";")
        thread = "?"
        if frames and (match := _THREAD.match(frames[0])):
            thread = match["name"] or names.get(int(match["id"], 0), match["id"])
            frames = frames[1:]
        frames = [frame for frame in frames if not frame.startswith("process ")]
        profile.samples += count
        profile.threads[thread] += count
        if frames:
            profile.self_time[frame_name(frames[-1])] += count
        for name in {frame_name(frame) for frame in frames}:
            profile.inclusive[name] += count
    return profile


def record_command(pid: int, seconds: float, output: Path, gil: bool) -> list[str]:
    command = [str(PY_SPY), "record", "--pid", str(pid), "--duration", f"{seconds:g}"]
    command += ["--rate", str(RATE), "--format", "raw", "--threads", "--nonblocking"]
    command += ["--output", str(output)]
    return [*command, "--gil"] if gil else command


def thread_names(pid: int) -> dict[int, str]:
    """OS thread id -> Python thread name, from one ``py-spy dump --json``."""
    done = subprocess.run(
        [str(PY_SPY), "dump", "--pid", str(pid), "--json", "--nonblocking"],
        capture_output=True,
        text=True,
        check=False,
        timeout=20,
    )
    try:
        threads = json.loads(done.stdout)
    except json.JSONDecodeError:
        return {}
    return {
        int(thread["os_thread_id"]): str(thread.get("thread_name") or thread["thread_id"])
        for thread in threads
        if thread.get("os_thread_id") is not None
    }


# --- one profiled flow ------------------------------------------------------------------------


@dataclass
class Sampled:
    """What was measured while the flow published."""

    wall: float = 0.0
    busy: Profile = field(default_factory=Profile)
    gil: Profile = field(default_factory=Profile)
    process_cpu: dict[str, float] = field(default_factory=dict)  # role -> % of one core
    thread_cpu: dict[str, float] = field(default_factory=dict)  # bridge thread -> % of one core
    errors: list[str] = field(default_factory=list)


def sample(bridge_pid: int, topic: str, seconds: float, out: Sampled) -> None:
    """Runs inside the flow once publishing started: py-spy on the bridge, CPU of all three."""
    pids = {role_of(pid): pid for pid in pids_with(topic) if pid != os.getpid()}
    pids["bridge"] = bridge_pid
    names = thread_names(bridge_pid)
    with tempfile.TemporaryDirectory() as tmp:
        outputs = {"busy": Path(tmp) / "busy.txt", "gil": Path(tmp) / "gil.txt"}
        start = time.monotonic()
        cpu0 = {role: cpu_seconds(pid) for role, pid in pids.items()}
        tasks0 = task_cpu(bridge_pid)
        spies = [
            subprocess.Popen(
                record_command(bridge_pid, seconds, path, name == "gil"),
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
            )
            for name, path in outputs.items()
        ]
        for spy in spies:
            _, err = spy.communicate(timeout=seconds + 30)
            if spy.returncode:
                out.errors.append(err.strip()[-300:])
        out.wall = time.monotonic() - start
        cpu1 = {role: cpu_seconds(pid) for role, pid in pids.items()}
        tasks1 = task_cpu(bridge_pid)
        for name, path in outputs.items():
            if path.exists():
                with path.open(encoding="utf-8") as raw:
                    setattr(out, name, parse_raw(raw, names))
    out.process_cpu = {role: 100 * (cpu1[role] - cpu0[role]) / out.wall for role in pids}
    others = 0.0
    for tid, end in tasks1.items():
        share = 100 * (end - tasks0.get(tid, 0.0)) / out.wall
        known = names.get(tid)
        if known is not None:
            name = known
        elif share < 1:
            others += share
            continue
        else:
            name = f"native {task_comm(bridge_pid, tid)} ({tid})"
        out.thread_cpu[name] = out.thread_cpu.get(name, 0.0) + share
    out.thread_cpu["other native threads (< 1% each)"] = others


# --- report -----------------------------------------------------------------------------------


def pct(part: float, whole: float) -> str:
    return f"{100 * part / whole:.0f}%" if whole else "-"


def function_table(got: Sampled, ticks: float, top: int) -> str:
    busy, gil = got.busy, got.gil
    rows = [
        "| function (file) | self | inclusive | self, GIL held | inclusive, GIL held |",
        "|---|---|---|---|---|",
    ]
    ranked = sorted(busy.inclusive, key=lambda name: (-busy.self_time[name], -busy.inclusive[name]))
    for name in ranked[:top]:
        own, inclusive = pct(busy.self_time[name], ticks), pct(busy.inclusive[name], ticks)
        own_gil, inclusive_gil = pct(gil.self_time[name], ticks), pct(gil.inclusive[name], ticks)
        rows.append(f"| `{name}` | {own} | {inclusive} | {own_gil} | {inclusive_gil} |")
    return "\n".join(rows)


def thread_table(got: Sampled, ticks: float) -> str:
    rows = [
        "| thread | CPU (% of one core, /proc) | busy samples (py-spy) | holds the GIL |",
        "|---|---|---|---|",
    ]
    names = sorted(
        set(got.thread_cpu) | set(got.busy.threads),
        key=lambda name: -max(got.thread_cpu.get(name, 0.0), 100 * got.busy.threads[name] / ticks),
    )
    for name in names:
        cpu = got.thread_cpu.get(name)
        rows.append(
            f"| {name} | {'-' if cpu is None else f'{cpu:.0f}%'} | "
            f"{pct(got.busy.threads[name], ticks)} | {pct(got.gil.threads[name], ticks)} |"
        )
    return "\n".join(rows)


def conclusion(result: FlowResult, got: Sampled, ticks: float, seconds: float) -> str:
    cpu = got.process_cpu
    total = sum(cpu.values())
    bridge, pub, sub = cpu.get("bridge", 0.0), cpu.get("gz-pub", 0.0), cpu.get("ros-sub", 0.0)
    gil = 100 * got.gil.samples / ticks

    def wall(profile: Profile, *needles: str) -> float:
        hits = [n for n in profile.inclusive if any(n.startswith(needle) for needle in needles)]
        return max((100 * profile.inclusive[name] / ticks for name in hits), default=0.0)

    publish = wall(got.busy, "SerializedPublisher.publish ")
    publish_gil = wall(got.gil, "SerializedPublisher.publish ")
    convert = wall(got.busy, "gz_to_ros_cdr ")
    convert_gil = wall(got.gil, "gz_to_ros_cdr ")
    delivery_cpu = sum(cpu_ for name, cpu_ in got.thread_cpu.items() if name.startswith("gz-sub "))
    zmq_io = sum(cpu_ for name, cpu_ in got.thread_cpu.items() if "ZMQbg/IO" in name)
    ms = 1000 / result.rate if result.rate else 0.0
    kept = result.received / result.sent if result.sent else 0.0
    return f"""**Conclusion.** {result.rate:.0f} msg/s arrived ({ms:.1f} ms per image); the Gazebo
publisher sent {result.sent} images in {seconds:g} s and {result.received} ({kept:.0%}) reached the
subscriber. Over the sampled window the bridge process used {bridge:.0f}% of one core, the
Gazebo publisher {pub:.0f}% and the rclpy subscriber {sub:.0f}%: {total:.0f}% of the 200% the 2
cores offer. The image delivery thread takes the bulk path: `gz_to_ros_cdr` (split the payload,
convert the small fields, write the CDR around the 6.2 MB data in the received frame) is on its
stack in {convert:.0f}% of the ticks and holds the GIL in {convert_gil:.0f}%;
`SerializedPublisher.publish`
(`rcl_publish_serialized_message` through ctypes: Fast DDS copies the frame into shared memory
and hands it to the subscriber) in {publish:.0f}%, holding the GIL in only {publish_gil:.0f}%
because ctypes releases it, so the other channels' threads run meanwhile. That thread used
{delivery_cpu:.0f}% of a core; some thread of the bridge held the GIL in {gil:.0f}% of the ticks.
libzmq's I/O thread used {zmq_io:.0f}% of a core receiving frames: a Gazebo publisher has no
flow control beyond TCP's (the channel's own connection; what does not fit is dropped at the
publisher), so flat out it sends more than the bridge converts, and the bridge pays the TCP
receive of frames its bounded queue then drops to keep the newest. What
bounds the rate is therefore the machine: three processes moving 6 MB frames with, per frame
delivered, the publisher's serialization, two kernel TCP copies, Fast DDS's copies (the
bridge itself copies nothing of a camera's frame) and the subscriber's deserialization, plus
the receive cost of the dropped frames; the ceiling moves each frame with rclpy alone, in two
processes."""


def markdown(
    result: FlowResult, got: Sampled, seconds: float, sample_s: float, *, command: str, top: int
) -> str:
    ticks = RATE * sample_s
    spy = " ".join(record_command(0, sample_s, Path("OUT"), False)).replace(str(BIN) + "/", "")
    spy = spy.replace("--pid 0", "--pid <bridge pid>")
    errors = "\n".join(f"- py-spy error: `{e}`" for e in got.errors)
    processes = ", ".join(f"{role} {share:.0f}%" for role, share in got.process_cpu.items())
    return f"""## Profile of the 1080p GZ->ROS image path (issue 5)

Command: `{command}`

The images benchmark's flow "Gazebo publisher -> parameter_bridge Image channel (ZeroMQ) ->
rclpy subscriber", 1920x1080 rgb8, flat out, {seconds:g} s of publishing: {result.rate:.0f}
msg/s, {result.received}/{result.sent} received, median {result.median_us / 1000:.1f} ms. While it
published the bridge process was sampled for {got.wall:.1f} s with `{spy}` (pid of the bridge),
and at the same time with the same command plus `--gil` (only the thread holding the GIL). Shares
are of the {ticks:.0f} sample ticks ({RATE} Hz); idle samples (threads waiting) are not recorded,
so a thread's share is the time it was running Python code or a native call made from Python.
"self" is time in the function itself (including the C it calls directly), "inclusive" adds its
callees. CPU by process over the same window (% of one core, /proc/<pid>/stat): {processes}.
{errors}

Top functions of the bridge (by self time):

{function_table(got, ticks, top)}

Bridge threads (CPU from /proc/<pid>/task/<tid>/stat; names from `py-spy dump --json`):

{thread_table(got, ticks)}

{conclusion(result, got, ticks, seconds)}
"""


def run(seconds: float, sample_s: float) -> tuple[FlowResult, Sampled]:
    which = backend("zeromq")
    topic = topic_name("prof_image1080")
    got = Sampled()
    with bridge_process([bridge_argument(topic, KIND, "gz2ros")], which.bridge_env) as bridge:
        if bridge is None:
            return FlowResult(0, 0, 0.0, 0.0, 0.0, None, "bridge did not start"), got
        pid = bridge.pid

        def during() -> None:
            time.sleep(1.0)  # past the first burst
            sample(pid, topic, sample_s, got)

        result = flow_through(
            Flow("gz-pub", "ros-sub", KIND, seconds, 0.0), topic, which, bridge, during
        )
    return result, got


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=14.0, help="publishing time")
    parser.add_argument("--sample", type=float, default=10.0, help="py-spy sampling time")
    parser.add_argument("--top", type=int, default=12, help="functions listed")
    args = parser.parse_args(argv)
    if args.sample + 2 > args.seconds:
        parser.error("--sample must be at least 2 s shorter than --seconds")
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    result, got = run(args.seconds, args.sample)
    if result.error or not got.busy.samples:
        print(f"no profile: {result.error or got.errors}", file=sys.stderr)
        return 1
    command = (
        f".venv/bin/python -m benchmarks.profile_images --seconds {args.seconds:g} "
        f"--sample {args.sample:g}"
    )
    write_section(
        "profile", markdown(result, got, args.seconds, args.sample, command=command, top=args.top)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
