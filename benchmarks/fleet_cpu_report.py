"""The report that ``benchmarks.fleet_cpu_map`` writes (``benchmarks/reports/fleet_cpu_map.md``)
from what it found (``fleet_cpu_figures.CpuMap``): the bridge's CPU per delivered message by
thread, by stage, by cross-cut, beside the same run's rclpy ceiling, and issue 36's candidates,
with the biggest items named."""

from __future__ import annotations

import argparse
from collections import Counter
from collections.abc import Sequence

from benchmarks.bridge_threads import ORDER
from benchmarks.fleet_cpu_figures import CpuMap
from benchmarks.fleet_goals import total_offered

#: The thread that carries the Gazebo -> ROS messages, the bulk of a fleet's.
LOOP = ORDER[0]
#: A role whose CPU is at least this share of the bridge's gets its profile shown.
SHOWN_ROLE = 0.03
#: A stage at least this share of its role's samples gets a row; the rest are summed.
SHOWN_STAGE = 0.02
WAIT = "wait for work (epoll_wait, poll)"
SCHEDULING = "kernel: not in a system call (interrupts, scheduling)"
PUBLISH = "publish through rcl (rmw, Fast DDS)"
TAKE = "take through rcl (rmw, Fast DDS)"
RECEIVE = "receive from libzmq (zmq_msg_recv)"
GETSOCKOPT = "zmq_getsockopt (ZMQ_EVENTS)"
IN_SYSCALLS = "in system calls"
CUTS = (
    IN_SYSCALLS,
    "waking another thread",
    "copying memory (memcpy, memmove)",
    "allocating and freeing",
    "the Python interpreter itself",
    "switched out and back in (the scheduler)",
)


def _calls_text(calls: dict[str, float], top: int = 4) -> str:
    if not calls:
        return "-"
    named = ", ".join(f"{name} {n:.2f}" for name, n in list(calls.items())[:top])
    return f"{sum(calls.values()):.2f} ({named})"


def _threads_table(found: CpuMap) -> list[str]:
    lines = [
        "| threads (OS names) | CPU, % of a core | µs per delivered message | share "
        "| wake-ups per message (voluntary switches) | preemptions per message "
        "| system calls per message (the most frequent) |",
        "|---|---|---|---|---|---|---|",
    ]
    total = found.total_us or 1.0
    for role in found.present():
        use = found.roles[role]
        names = ", ".join(sorted(use.names))
        lines.append(
            f"| {role} ({use.threads}: {names}) | {100 * use.cpu_s / found.clean.seconds:.1f}% "
            f"| {found.us(role):.2f} | {found.us(role) / total:.0%} "
            f"| {found.per(role, lambda u: u.voluntary):.2f} "
            f"| {found.per(role, lambda u: u.involuntary):.2f} "
            f"| {_calls_text(found.calls(role))} |"
        )
    every: Counter[str] = Counter()
    for role in found.present():
        every.update(found.calls(role))
    wakes = sum(found.per(role, lambda u: u.voluntary) for role in found.present())
    preempted = sum(found.per(role, lambda u: u.involuntary) for role in found.present())
    lines.append(
        f"| **the bridge** | {found.cpu_percent:.1f}% | **{found.total_us:.2f}** | 100% "
        f"| {wakes:.2f} | {preempted:.2f} | {_calls_text(dict(every.most_common()))} |"
    )
    return lines


def _shown_roles(found: CpuMap) -> list[str]:
    total = found.total_us or 1.0
    return [r for r in found.present() if r in found.profiles and found.us(r) / total >= SHOWN_ROLE]


def _stages_table(found: CpuMap) -> list[str]:
    lines = [
        "| threads | stage | share of the threads' samples | µs per delivered message |",
        "|---|---|---|---|",
    ]
    for role in _shown_roles(found):
        profile = found.profiles[role]
        rest, rest_n = 0.0, 0
        for stage, count in profile.stages.most_common():
            if profile.share(count) >= SHOWN_STAGE:
                lines.append(
                    f"| {role} ({profile.samples} samples) | {stage} "
                    f"| {profile.share(count):.0%} | {found.stage_us(role, stage):.2f} |"
                )
            else:
                rest += profile.share(count)
                rest_n += 1
        if rest_n:
            lines.append(
                f"| {role} | the rest ({rest_n} stage{'s' if rest_n > 1 else ''}, each under "
                f"{SHOWN_STAGE:.0%}) | "
                f"{rest:.0%} | {rest * found.us(role):.2f} |"
            )
    return lines


def _parts_table(found: CpuMap) -> list[str]:
    """Inside publishing and taking through rcl, on the threads shown."""
    lines = [
        "| threads | stage | where in Fast DDS | share of the stage | µs per delivered message |",
        "|---|---|---|---|---|",
    ]
    for role in _shown_roles(found):
        profile = found.profiles[role]
        for stage in (PUBLISH, TAKE):
            inside = [(n, part) for (where, part), n in profile.parts.items() if where == stage]
            whole = sum(n for n, _ in inside)
            for n, part in sorted(inside, reverse=True):
                lines.append(
                    f"| {role} | {stage} | {part} | {n / whole:.0%} "
                    f"| {found.part_us(role, stage, part):.2f} |"
                )
    return lines if len(lines) > 2 else []


def _cuts_table(found: CpuMap) -> list[str]:
    lines = [
        "| threads | " + " | ".join(CUTS) + " | the system calls, µs each per message |",
        "|---|" + "---|" * (len(CUTS) + 1),
    ]
    for role in _shown_roles(found):
        profile = found.profiles[role]
        calls = [
            (found.cut_us(role, cut), cut.removeprefix("in system call "))
            for cut in profile.cuts
            if cut.startswith("in system call ")
        ]
        top = ", ".join(f"{name} {us:.2f}" for us, name in sorted(calls, reverse=True)[:4])
        cells = " | ".join(f"{found.cut_us(role, cut):.2f}" for cut in CUTS)
        lines.append(f"| {role} | {cells} | {top or '-'} |")
    return lines


def _against_ceiling(found: CpuMap, ceiling: CpuMap) -> list[str]:
    """Each stage over every thread, the bridge beside the same run's ceiling."""
    mine, theirs = found.stage_totals(), ceiling.stage_totals()
    rows = sorted(
        ((mine.get(stage, 0.0), theirs.get(stage, 0.0), stage) for stage in {*mine, *theirs}),
        key=lambda row: row[1] - row[0],
    )
    lines = [
        "| stage (every thread together) | bridge, µs per delivered message | rclpy ceiling "
        "| bridge - ceiling |",
        "|---|---|---|---|",
    ]
    for bridge_us, ceiling_us, stage in rows:
        if max(bridge_us, ceiling_us) >= 0.1:
            lines.append(
                f"| {stage} | {bridge_us:.2f} | {ceiling_us:.2f} | {bridge_us - ceiling_us:+.2f} |"
            )
    lines.append(
        f"| **all** | **{found.total_us:.2f}** | **{ceiling.total_us:.2f}** "
        f"| **{found.total_us - ceiling.total_us:+.2f}** |"
    )
    return lines


def _ceiling_lines(found: CpuMap, ceiling: CpuMap) -> list[str]:
    threads = "; ".join(
        f"{role} {ceiling.us(role):.2f} µs"
        for role in ceiling.present()
        if ceiling.us(role) >= 0.05
    )
    lines = [
        f"The same run's rclpy ceiling (one rclpy process in the bridge's place; 1-minute load "
        f"average {ceiling.load:.2f} at its start): **{ceiling.cpu_percent:.1f}% of a core**, "
        f"{ceiling.rate:,.0f} messages a second delivered, **{ceiling.total_us:.2f} µs per "
        f"delivered message**, the bridge {found.total_us / (ceiling.total_us or 1.0):.2f}x that. "
        f"By thread: {threads}.",
        *(f"- {note}" for note in ceiling.notes),
    ]
    if found.profiles and ceiling.profiles:
        lines += [
            "",
            "By stage, every thread together, the bridge beside the ceiling (the stages where "
            "the bridge spends more first):",
            "",
            *_against_ceiling(found, ceiling),
        ]
    return lines


def _size_lines(found: CpuMap, args: argparse.Namespace) -> list[str]:
    lines = [
        f"### {found.robots} robots ({1 + 4 * found.robots} entries, "
        f"{total_offered(found.robots):,.0f} messages a second offered)",
        "",
        f"1-minute load average {found.load:.2f} at the start. Over the clean window of "
        f"{found.clean.seconds:.0f} s the bridge used **{found.cpu_percent:.1f}% of a core** and "
        f"its subscribers took {found.rate:,.0f} messages a second (Gazebo -> ROS "
        f"{found.clean.gz_to_ros / found.clean.seconds:,.0f}, `cmd_vel` "
        f"{found.clean.commands * found.commanded / found.clean.seconds:,.0f}): "
        f"**{found.total_us:.2f} µs of CPU per delivered message**. System calls counted over "
        f"{found.syscall_window.seconds:.0f} s, the profile over "
        f"{found.profile_window.seconds:.0f} s ({args.hz} samples a CPU second).",
        *(f"- {note}" for note in found.notes),
        "",
        "Per thread role, clean window:",
        "",
        *_threads_table(found),
    ]
    if found.profiles:
        lines += [
            "",
            f"Stages of the threads with {SHOWN_ROLE:.0%} or more of the bridge's CPU (perf "
            "samples; each stage's µs is its share of the threads' samples times their µs "
            "above):",
            "",
            *_stages_table(found),
            "",
            "Inside publishing and taking through rcl: where in Fast DDS, by the innermost frame "
            "naming one of its parts:",
            "",
            *(_parts_table(found) or ["- no samples there"]),
            "",
            "Cross-cuts of the same samples (they overlap the stages and each other), µs per "
            "delivered message:",
            "",
            *_cuts_table(found),
        ]
    return lines


def _candidates(maps: Sequence[CpuMap]) -> list[str]:
    """Issue 36's candidates, a column per fleet size."""

    def loop_wake(found: CpuMap) -> str:
        wakes = found.per(LOOP, lambda use: use.voluntary)
        per = f" ({1 / wakes:.1f} messages a wake-up)" if wakes else ""
        cost = found.stage_us(LOOP, WAIT) + found.stage_us(LOOP, SCHEDULING)
        everyone = sum(found.per(role, lambda use: use.voluntary) for role in found.present())
        return (
            f"loop {wakes:.2f} wake-ups per message{per}; its waiting and scheduling "
            f"{cost:.2f} µs; every thread {everyone:.2f} wake-ups per message"
        )

    def loop_calls(found: CpuMap) -> str:
        return (
            f"loop {_calls_text(found.calls(LOOP), 5)}; {found.cut_us(LOOP, IN_SYSCALLS):.2f} "
            f"µs in them; every thread {found.all_cut_us(IN_SYSCALLS):.2f} µs in system calls"
        )

    def getsockopt(found: CpuMap) -> str:
        calls = found.calls(LOOP)
        checks = ("poll", "getpid", "read")
        under = {
            stage: sum(found.call_us(LOOP, stage, call) for call in checks)
            for stage in (GETSOCKOPT, RECEIVE)
        }
        return (
            f"{found.stage_us(LOOP, GETSOCKOPT):.2f} µs under zmq_getsockopt on the loop; its "
            + ", ".join(f"{call} {calls.get(call, 0):.2f}" for call in checks)
            + f" calls per message take {under[RECEIVE]:.2f} µs under zmq_msg_recv and "
            f"{under[GETSOCKOPT]:.2f} µs under zmq_getsockopt"
        )

    def eventfd(found: CpuMap) -> str:
        io = "libzmq I/O"
        writes = found.calls(io).get("write", 0.0)
        return (
            f"libzmq I/O {writes:.2f} writes per message, "
            f"{found.cut_us(io, 'in system call write'):.2f} µs; waking another thread, every "
            f"thread: {found.all_cut_us('waking another thread'):.2f} µs"
        )

    def copies(found: CpuMap) -> str:
        cut = "copying memory (memcpy, memmove)"
        return f"{found.all_cut_us(cut):.2f} µs (the loop {found.cut_us(LOOP, cut):.2f})"

    def python(found: CpuMap) -> str:
        cut = "the Python interpreter itself"
        return f"{found.all_cut_us(cut):.2f} µs (the loop {found.cut_us(LOOP, cut):.2f})"

    def publish(found: CpuMap) -> str:
        dds = sum(found.us(role) for role in found.present() if role.startswith("Fast DDS"))
        return (
            f"publishing on the loop {found.stage_us(LOOP, PUBLISH):.2f} µs; Fast DDS's own "
            f"threads {dds:.2f} µs; libzmq's I/O thread {found.us('libzmq I/O'):.2f} µs"
        )

    rows = (
        ("one wake-up per message (batching across channels)", loop_wake),
        ("per-message system calls", loop_calls),
        ("zmq_getsockopt(ZMQ_EVENTS)", getsockopt),
        ("eventfd writes (libzmq's I/O thread signalling the socket)", eventfd),
        ("copies between the ZeroMQ frame and the ROS message", copies),
        ("per-message Python", python),
        ("beside them: the ROS side and the I/O threads", publish),
    )
    lines = [
        "| candidate (issue 36) | " + " | ".join(f"{m.robots} robots" for m in maps) + " |",
        "|---|" + "---|" * len(maps),
    ]
    for name, cell in rows:
        lines.append(f"| {name} | " + " | ".join(cell(found) for found in maps) + " |")
    return lines


def biggest(found: CpuMap, ceiling: CpuMap | None = None, top: int = 5) -> list[str]:
    """The biggest items per message, with how far the first is ahead of the next, and the
    stage where the bridge spends most over the ceiling."""
    items = found.items()[:top]
    if not items:
        return [f"- {found.robots} robots: no profile"]
    total = found.total_us or 1.0
    first = items[0]
    ahead = f", {first[0] / items[1][0]:.1f}x the next" if len(items) > 1 and items[1][0] else ""
    lines = [
        f"- {found.robots} robots: the biggest item is **{first[2]}** on the {first[1]} "
        f"threads: {first[0]:.2f} of {found.total_us:.2f} µs per message ({first[0] / total:.0%})"
        f"{ahead}. Then: "
        + "; ".join(f"{stage} ({role}) {us:.2f} µs" for us, role, stage in items[1:])
    ]
    if ceiling is not None and ceiling.profiles:
        mine, theirs = found.stage_totals(), ceiling.stage_totals()
        excess = sorted(((mine[s] - theirs.get(s, 0.0), s) for s in mine), reverse=True)[:3]
        lines.append(
            f"  Over the ceiling ({found.total_us:.2f} against {ceiling.total_us:.2f} µs): "
            + "; ".join(f"{stage} {more:+.2f} µs" for more, stage in excess)
        )
    return lines


def section(maps: Sequence[CpuMap], args: argparse.Namespace, loads: tuple[float, float]) -> str:
    bridges = [found for found in maps if not found.ceiling]
    ceilings = {found.robots: found for found in maps if found.ceiling}
    robots = " ".join(str(found.robots) for found in bridges)
    kinds = sorted({found.loop_kind() for found in bridges})
    lines = [
        "## Where a fleet message's CPU goes (issue 36 item 1)",
        "",
        f"Command: `.venv/bin/python -m benchmarks.fleet_cpu_map --robots {robots} --seconds "
        f"{args.seconds:g} --syscall-seconds {args.syscall_seconds:g} --profile-seconds "
        f"{args.profile_seconds:g} --hz {args.hz}`. 1-minute load average {loads[0]:.2f} "
        f"before and {loads[1]:.2f} after; 2 cores shared with other work.",
        "",
        f"**Measured on {' and '.join(kinds)}.** The module reads the bridge from outside "
        "only (thread names, `/proc`, perf), so it runs unchanged on any arrangement of the "
        "bridge's threads and sockets.",
        "",
        "The fleet of `benchmarks.fleet` as users run it (the C++ simulator, one "
        "`parameter_bridge`, `/clock` and every ten robots in subscriber processes of their "
        "own), bridged, then three windows one after the other: a clean one, with nothing "
        "attached, for each thread's CPU (`/proc/<pid>/task/<tid>/schedstat`) and context "
        "switches (`status`: a voluntary one is the thread going to sleep, so a wake-up to "
        "come; an involuntary one a preemption); one for system calls, counted per thread in "
        "the kernel (`perf stat --per-thread` on the syscall tracepoints; the thread runs on "
        "undisturbed); one for a profile (`perf record -e cpu-clock --call-graph dwarf`, "
        "every thread). Each figure is per message the subscribers took in its window, both "
        "directions. Threads are grouped by their OS names. A sample's stage is the "
        "outermost entry point of a library on the message path on its stack (`rcl_publish*`, "
        "`rcl_take*`, `zmq_msg_recv`, `zmq_msg_send`, `zmq_getsockopt`, `epoll_wait`/`poll`); "
        "under none, where it was: a system call by name, else the library of its innermost "
        "frame. Stages do not overlap; the cross-cuts (time in system calls, waking another "
        "thread, copying, allocating, the Python interpreter) cut across them. "
        "`perf stat -e instructions` is not supported on this machine's virtual CPU, so "
        "instruction counts are not given; callgrind, which would count them, slows the "
        "bridge fifty-fold, far below this fleet's rate, and changes how many messages each "
        "wake-up finds, which is one of the things measured.",
        "",
    ]
    for found in bridges:
        lines += [*_size_lines(found, args), ""]
        if found.robots in ceilings:
            lines += [*_ceiling_lines(found, ceilings[found.robots]), ""]
    lines += [
        "### Issue 36's candidates, per delivered message",
        "",
        *_candidates(bridges),
        "",
        "The biggest items per message (stages, which do not overlap):",
        "",
    ]
    for found in bridges:
        lines += biggest(found, ceilings.get(found.robots))
    return "\n".join(lines)
