"""Where a running process's threads spend their CPU, from ``perf record`` samples with their
call stacks, sorted into stages by the libraries' own entry points.

``perf record -e cpu-clock -F HZ --call-graph dwarf -p PID`` samples each thread while it runs
(``cpu-clock`` is a software event: it works in a VM without hardware counters), with the
stack unwound from DWARF, so libraries built without frame pointers (libzmq, Fast DDS,
Python) unwind too. ``perf script`` prints each sample's thread and frames; a sample's
**stage** is the outermost frame, from the thread's root down, that is a known entry point of
the libraries on the message path (:data:`STAGES`: publishing or taking through rcl, receiving
or sending through libzmq, ``zmq_getsockopt``, waiting in ``epoll_wait``/``poll``). Those
names are the libraries' public interfaces, not ours, so the stages hold however our loops are
arranged. A sample under none of them is put by where it was: in the kernel, by the system call
it was in; otherwise by the library of its innermost frame (our extension, the Python
interpreter, the C library, ...). Beside the stages, **cross-cuts** that may overlap them: the
time in system calls (each by name), waking another thread, copying memory, allocating, and the
Python interpreter itself.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

#: Stages by an entry point on the stack, outermost first wins.
STAGES = (
    ("publish through rcl (rmw, Fast DDS)", re.compile(r"^(rcl_publish|rmw_publish)")),
    ("take through rcl (rmw, Fast DDS)", re.compile(r"^(rcl_take|rmw_take)")),
    ("receive from libzmq (zmq_msg_recv)", re.compile(r"^zmq_(msg_recv|recv|recvmsg|recviov)$")),
    ("send through libzmq (zmq_msg_send)", re.compile(r"^zmq_(msg_send|send|sendmsg|send_const)$")),
    ("zmq_getsockopt (ZMQ_EVENTS)", re.compile(r"^zmq_getsockopt$")),
    ("wait for work (epoll_wait, poll)", re.compile(r"^(__)?(epoll_wait|epoll_pwait|poll|ppoll)$")),
)
#: Inside publishing or taking through rcl: where in Fast DDS, by the innermost frame that
#: names one of these parts (Fast DDS's own classes, which our code does not name).
PARTS = (
    ("statistics (Fast DDS's statistics module)", re.compile(r"statistics::")),
    (
        "shared-memory transport: the payload into each reader's port, its semaphore posted",
        re.compile(r"SharedMem|semaphore_post|shared_memory|interprocess"),
    ),
    (
        "Fast DDS's event thread told (timers re-armed: ResourceEvent, TimedEvent)",
        re.compile(r"ResourceEvent|TimedEvent"),
    ),
    (
        "RTPS messages and each reader's state (RTPSMessageGroup, ReaderProxy)",
        re.compile(
            r"RTPSMessage|ReaderProxy|LocatorSelector|deliver_sample|send_nts|ReaderLocator"
        ),
    ),
    (
        "history and payload pool (changes, payloads)",
        re.compile(r"History|CacheChange|PayloadPool|change_pool|prepare_change|SerializedPayload"),
    ),
    (
        "the data writer and the flow controller",
        re.compile(r"DataWriter|FlowController|RTPSWriter|StatefulWriter"),
    ),
    ("rcl, rmw", re.compile(r"^(rcl|rmw)")),
)
#: Libraries by the file name of a frame's object, first match wins.
LIBRARIES = (
    ("our C extension", re.compile(r"_native\.cpython")),
    ("Python interpreter", re.compile(r"libpython|/python3[.\d]*$|\.cpython-|\.abi3\.so")),
    ("libzmq", re.compile(r"libzmq")),
    ("Fast DDS", re.compile(r"libfast(rtps|dds|cdr)")),
    ("rcl, rmw, rclpy", re.compile(r"librcl|librmw|librcutils|librosidl|libtracetools|_rclpy")),
    ("C and C++ runtime", re.compile(r"libc\.so|libstdc\+\+|libm\.so|libgcc|ld-linux|\[vdso\]")),
)
KERNEL = "[kernel.kallsyms]"
#: A kernel frame that names a system call: its handler (``__x64_sys_poll``) or, where the
#: kernel inlined that, the function it calls (``ksys_write``, ``__sys_recvfrom``).
SYSCALL = re.compile(r"^(?:__x64_sys|__se_sys|__do_sys|__ia32_sys|ksys|__sys|do_sys)_(\w+)$")
#: The kernel's system call entry, whose callee is the handler, and its way back, where a
#: thread that woke another is often switched out.
ENTRY = "do_syscall_64"
RETURN = "exit_to_user_mode_loop"
#: Cross-cuts: a name and a test on a sample's frames (innermost first).
SWITCHED = re.compile(r"^(__schedule|finish_task_switch)")
WAKE = re.compile(r"^(try_to_wake_up|wake_up_q)$")
COPY = re.compile(r"^(__)?mem(cpy|move)")
ALLOC = re.compile(r"^(__libc_|_int_)?(malloc|free|realloc|calloc|cfree)|^operator (new|delete)")


@dataclass(frozen=True)
class Frame:
    symbol: str
    #: The object's path as perf prints it (``[kernel.kallsyms]``, a file).
    library: str
    ip: int = 0


@dataclass(frozen=True)
class Sample:
    comm: str
    tid: int
    #: Innermost first.
    frames: tuple[Frame, ...]


def missing() -> str | None:
    """Why a profile cannot be taken here, or None."""
    return "perf is not installed" if shutil.which("perf") is None else None


def record(pid: int, seconds: float, hz: int, output: Path) -> None:
    """Sample ``pid``'s threads for ``seconds`` into ``output``."""
    output.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        [
            "perf", "record", "-q", "-e", "cpu-clock", "-F", str(hz), "--call-graph",
            "dwarf,16384", "-p", str(pid), "-o", str(output), "--", "sleep", f"{seconds:g}",
        ],
        check=True, capture_output=True, timeout=seconds + 120,
    )  # fmt: skip


def samples(data: Path) -> Iterator[Sample]:
    """The samples of a ``perf record`` file (``perf script``)."""
    script = subprocess.run(
        ["perf", "script", "-i", str(data), "-F", "comm,tid,ip,sym,dso"],
        check=True, capture_output=True, text=True, errors="replace", timeout=1800,
    )  # fmt: skip
    yield from parse(script.stdout)


#: A sample's head line (``comm tid``, the name may hold spaces) and a frame's line.
HEAD = re.compile(r"^(\S.*?)\s+(\d+)\s*$")
FRAME = re.compile(r"^\s+([0-9a-f]+)\s+(.*?)\s+\((.*)\)\s*$")
#: What ``perf script`` prints for the object of a function inlined into the next frame.
INLINED = "inlined"


def parse(text: str) -> Iterator[Sample]:
    """``perf script -F comm,tid,ip,sym,dso`` output (with call stacks) as samples."""
    head: tuple[str, int] | None = None
    frames: list[Frame] = []
    for line in [*text.splitlines(), ""]:
        if not line.strip():
            if head is not None:
                yield Sample(head[0], head[1], _resolved(frames))
            head, frames = None, []
            continue
        if head is None:
            if match := HEAD.match(line):
                head = (match[1], int(match[2]))
            continue
        if match := FRAME.match(line):
            symbol = re.sub(r"\+0x[0-9a-f]+$", "", match[2])
            frames.append(Frame(symbol, match[3], int(match[1], 16)))


def _resolved(frames: list[Frame]) -> tuple[Frame, ...]:
    """The frames with each inlined one given the object of the real frame at its address
    (the next frame with the same address; ``unknown`` where perf printed none)."""
    objects: dict[int, str] = {}
    for frame in frames:
        if frame.library != INLINED:
            objects.setdefault(frame.ip, frame.library)
    return tuple(
        Frame(f.symbol, objects.get(f.ip, "unknown"), f.ip) if f.library == INLINED else f
        for f in frames
    )


def library(path: str) -> str:
    """What a frame's object is (:data:`LIBRARIES`), ``kernel``, or its file name."""
    if path == KERNEL:
        return "kernel"
    name = next((name for name, pattern in LIBRARIES if pattern.search(path)), None)
    return name or Path(path).name


def syscall(sample: Sample) -> str | None:
    """The system call a sample is in, None if it is not in one: named by the frames just
    inside the kernel's entry, the outermost that names one (:data:`SYSCALL`)."""
    symbols = [frame.symbol for frame in sample.frames]
    if ENTRY not in symbols:
        return None
    inside = symbols[: symbols.index(ENTRY)]
    for symbol in reversed(inside):
        if match := SYSCALL.match(symbol):
            return match[1]
    if RETURN in inside:
        return "the return to user space (rescheduled there, rseq)"
    return "the entry"


def stage(sample: Sample) -> str:
    """The sample's stage (module docstring)."""
    for frame in reversed(sample.frames):
        for name, pattern in STAGES:
            if pattern.match(frame.symbol):
                return name
    if not sample.frames:
        return "no stack"
    if sample.frames[0].library == KERNEL:
        call = syscall(sample)
        return (
            f"kernel: {call}" if call else "kernel: not in a system call (interrupts, scheduling)"
        )
    return f"{library(sample.frames[0].library)} (outside the stages above)"


def part(sample: Sample, where: str) -> str | None:
    """Where in Fast DDS a sample of publishing or taking is (:data:`PARTS`, by the innermost
    frame that names a part), None for a sample of another stage (``where``)."""
    if not where.startswith(("publish", "take")):
        return None
    for frame in sample.frames:
        for name, pattern in PARTS:
            if pattern.search(frame.symbol):
                return name
    return "elsewhere (the kernel, the C library)"


def cross_cuts(sample: Sample) -> list[str]:
    """The cross-cuts a sample counts in (module docstring)."""
    cuts = []
    call = syscall(sample)
    if call:
        cuts += ["in system calls", f"in system call {call}"]
    if any(WAKE.match(frame.symbol) for frame in sample.frames):
        cuts.append("waking another thread")
    if any(SWITCHED.match(frame.symbol) for frame in sample.frames):
        cuts.append("switched out and back in (the scheduler)")
    leaf = sample.frames[0] if sample.frames else Frame("", "")
    if COPY.match(leaf.symbol):
        cuts.append("copying memory (memcpy, memmove)")
    if ALLOC.match(leaf.symbol):
        cuts.append("allocating and freeing")
    if library(leaf.library) == "Python interpreter":
        cuts.append("the Python interpreter itself")
    return cuts


@dataclass
class Profile:
    """One group of threads' samples, sorted."""

    samples: int = 0
    stages: Counter[str] = field(default_factory=Counter)
    cuts: Counter[str] = field(default_factory=Counter)
    #: Inside publishing and taking: (stage, part).
    parts: Counter[tuple[str, str]] = field(default_factory=Counter)
    #: The system calls by the stage they were made in: (stage, call).
    calls: Counter[tuple[str, str]] = field(default_factory=Counter)
    #: Innermost frames: ``symbol (library)``.
    leaves: Counter[str] = field(default_factory=Counter)

    def add(self, sample: Sample) -> None:
        self.samples += 1
        where = stage(sample)
        self.stages[where] += 1
        self.cuts.update(cross_cuts(sample))
        inside = part(sample, where)
        if inside is not None:
            self.parts[where, inside] += 1
        call = syscall(sample)
        if call is not None:
            self.calls[where, call] += 1
        if sample.frames:
            leaf = sample.frames[0]
            self.leaves[f"{leaf.symbol} ({library(leaf.library)})"] += 1

    def share(self, count: int) -> float:
        return count / self.samples if self.samples else 0.0
