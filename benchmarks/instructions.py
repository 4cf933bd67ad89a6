"""Instructions per message of the native conversion code, beside the Python path's: figures
that do not move with the machine's load, since callgrind counts instructions, not time.

Usage: ``.venv/bin/python -m benchmarks.instructions [--messages N] [--kinds clock odometry ...]
[--against REV]`` (needs valgrind); writes ``benchmarks/reports/instructions.md``. With
``--against``, the package of commit ``REV`` (its extension built in a temporary worktree) is
counted in the same run, beside this tree's: a before and after of a change to the native code.

One Python process runs under ``valgrind --tool=callgrind``, for each message kind of
``benchmarks.payloads`` that is not an image or a point cloud: the Gazebo -> ROS conversion
``N`` times natively (the pair's compiled program, ``Program.to_cdr``) and ``N`` times as the
Python path does it (``FromString``, ``to_ros``, the compiled CDR writer), then the
ROS -> Gazebo one natively (``Encoder.to_pb``) and as the Python path (the light CDR reader,
``to_gz``, ``SerializeToString``). Each run of ``N`` stands between two calls of a marker
function (``math.gcd``), before each of which callgrind writes what it counted since the last
(``--dump-before``): a phase's instructions are one dump's. The native figure is what the C
conversion function counted (``rgb_to_cdr``, ``rgb_to_pb``, with what they call), the cost of
the loop's call; the Python figure is the phase's, less a phase of ``N`` empty calls. The
driver checks first that both paths write the same bytes for the message measured.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from benchmarks.harness import ROOT
from benchmarks.payloads import KINDS
from benchmarks.report import write_section

#: The kinds measured by default: every kind a channel converts message by message.
DEFAULT_KINDS = ("clock", "twist", "odometry", "imu", "joint_states", "tf20", "tf50", "scan1440")
#: The C functions whose inclusive counts are the native figures, per direction.
NATIVE_FUNCTIONS = {"gz_to_ros": "rgb_to_cdr", "ros_to_gz": "rgb_to_pb"}
#: The marker: callgrind dumps what it counted before each call of this C function.
MARKER = "math_gcd"


@dataclass(frozen=True)
class Phase:
    """One run of ``messages`` calls of one operation, as the driver announces it."""

    kind: str
    direction: str  # "gz_to_ros", "ros_to_gz", or "" for the empty calls
    path: str  # "native", "python" or "empty"
    messages: int
    size_in: int = 0
    size_out: int = 0
    same_bytes: bool = True


# ---- the driver (runs under valgrind) -------------------------------------------------------


def _nothing() -> None:
    return None


def _operations(name: str) -> Iterator[tuple[Phase, Callable[[], object]]]:
    """Each measured operation of kind ``name``: its phase (with ``messages`` 0) and the call."""
    from rclpy.serialization import serialize_message  # noqa: PLC0415

    from ros_gz_bridge_py import native  # noqa: PLC0415
    from ros_gz_bridge_py.msgs import message_class  # noqa: PLC0415
    from ros_gz_bridge_py.native.encoder import compile_to_gz  # noqa: PLC0415
    from ros_gz_bridge_py.native.program import compile_to_ros  # noqa: PLC0415
    from ros_gz_bridge_py.native.words import NotExpressibleError  # noqa: PLC0415
    from ros_gz_bridge_py.ros import light_reader  # noqa: PLC0415
    from ros_gz_bridge_py.ros.cdr_writer import writer_for  # noqa: PLC0415

    extension = native.extension()
    if extension is None:
        msg = f"the native extension is missing: {native.unavailable_reason()}"
        raise SystemExit(msg)
    kind = KINDS[name]
    pair = kind.pair
    ros_msg = kind.make_ros()
    payload: bytes = pair.to_gz(ros_msg).SerializeToString()
    cdr: bytes = serialize_message(ros_msg)
    parse = message_class(pair.gz_type).FromString
    write = writer_for(pair.ros_class)
    if write is None:
        msg = f"{name}: no compiled CDR writer for {pair.ros_type}"
        raise SystemExit(msg)

    def python_to_ros() -> bytes:
        return write(pair.to_ros(parse(payload)))

    def python_to_gz() -> bytes:
        return bytes(pair.to_gz(light_reader.read(cdr, pair.ros_class)).SerializeToString())

    written = python_to_ros()
    encoded = python_to_gz()
    try:
        compiled = compile_to_ros(pair)
        program = extension.Program(compiled.schema, compiled.ops)
        status, out = program.to_cdr(payload)
        same = status == 0 and out == written
        phase = Phase(name, "gz_to_ros", "native", 0, len(payload), len(written), same)
        yield phase, lambda: program.to_cdr(payload)
    except NotExpressibleError:
        pass
    yield Phase(name, "gz_to_ros", "python", 0, len(payload), len(written)), python_to_ros
    try:
        encoder = extension.Encoder(compile_to_gz(pair))
        status, out = encoder.to_pb(cdr)
        same = status == 0 and out == encoded
        yield (
            Phase(name, "ros_to_gz", "native", 0, len(cdr), len(encoded), same),
            lambda: encoder.to_pb(cdr),
        )
    except NotExpressibleError:
        pass
    yield Phase(name, "ros_to_gz", "python", 0, len(cdr), len(encoded)), python_to_gz


def drive(messages: int, kinds: list[str]) -> None:
    """Under callgrind: each phase between two markers, announced on stdout as a JSON line
    (after the package measured)."""
    import ros_gz_bridge_py  # noqa: PLC0415

    print("package", ros_gz_bridge_py.__file__, flush=True)
    plan: list[tuple[Phase, Callable[[], object]]] = [(Phase("", "", "empty", 0), _nothing)]
    for name in kinds:
        plan.extend(_operations(name))
    for phase, operation in plan:
        for _ in range(3):  # first calls build caches; they are not what a message costs
            operation()
        print(json.dumps({**phase.__dict__, "messages": messages}), flush=True)
        math.gcd(1, 1)
        for _ in range(messages):
            operation()
        math.gcd(1, 1)


# ---- the measurement ------------------------------------------------------------------------


@dataclass(frozen=True)
class Counted:
    phase: Phase
    #: Instructions of the whole phase, and of the native function with its callees.
    total: int
    native: int


def _dumps(directory: Path) -> list[Path]:
    """The numbered dumps of the traced process, in order. They share one pid: the ROS wheels'
    bootstrapper re-executes Python in the same process, and only the driver calls the marker."""
    numbered = [p for p in directory.iterdir() if re.fullmatch(r"cg\.\d+\.\d+", p.name)]
    return sorted(numbered, key=lambda p: int(p.name.split(".")[2]))


def totals(text: str) -> int:
    """The instructions a callgrind dump counted (its ``totals:`` or ``summary:`` line)."""
    found = re.search(r"^(?:totals|summary):\s*(\d+)", text, re.MULTILINE)
    if found is None:
        msg = "a callgrind dump without a totals line"
        raise ValueError(msg)
    return int(found.group(1))


def inclusive(annotated: str, function: str) -> int:
    """``function``'s inclusive count in ``callgrind_annotate --inclusive=yes`` output (0
    when it does not appear)."""
    pattern = re.compile(rf"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?\S*:{re.escape(function)}\s")
    for line in annotated.splitlines():
        found = pattern.match(line)
        if found:
            return int(found.group(1).replace(",", ""))
    return 0


def measure(
    messages: int, kinds: list[str], work: Path, package: Path | None = None
) -> list[Counted]:
    """Runs the driver under callgrind (on the package found in ``package``, else this tree's)
    and counts each announced phase."""
    work.mkdir(parents=True)
    command = [
        "valgrind", "--tool=callgrind", "--trace-children=yes", f"--dump-before={MARKER}",
        f"--callgrind-out-file={work}/cg.%p", sys.executable, "-m", "benchmarks.instructions",
        "--driver", "--messages", str(messages), "--kinds", *kinds,
    ]  # fmt: skip
    # Run from `work`: ``-m`` puts the current folder first on the path, before PYTHONPATH.
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(str(p) for p in (package, ROOT) if p)}
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=work, check=False)
    if done.returncode != 0:
        msg = f"the driver under callgrind failed:\n{done.stderr[-3000:]}"
        raise RuntimeError(msg)
    loaded = next((line for line in done.stdout.splitlines() if line.startswith("package ")), "")
    if package is not None and str(package) not in loaded:
        msg = f"the driver did not load the package in {package}: {loaded}"
        raise RuntimeError(msg)
    phases = [Phase(**json.loads(line)) for line in done.stdout.splitlines() if line[:1] == "{"]
    dumps = _dumps(work)
    # Dump 2i holds phase i's calls: dump 2i-1 runs up to its first marker.
    if len(dumps) < 2 * len(phases):
        msg = f"{len(dumps)} callgrind dumps for {len(phases)} phases"
        raise RuntimeError(msg)
    counted = []
    for i, phase in enumerate(phases):
        dump = dumps[2 * i + 1]
        function = NATIVE_FUNCTIONS.get(phase.direction, "") if phase.path == "native" else ""
        native = 0
        if function:
            annotated = subprocess.run(
                ["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(dump)],
                capture_output=True, text=True, check=True,
            ).stdout  # fmt: skip
            native = inclusive(annotated, function)
        counted.append(Counted(phase, totals(dump.read_text(errors="replace")), native))
    return counted


@contextlib.contextmanager
def package_of(rev: str, work: Path) -> Iterator[Path]:
    """A folder holding only the package of commit ``rev``, its extension built (in a worktree
    removed after)."""
    tree = work / "tree"
    git = ["git", "-C", str(ROOT)]
    subprocess.run([*git, "worktree", "add", "--detach", str(tree), rev], check=True,
                   capture_output=True)  # fmt: skip
    try:
        subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"], cwd=tree,
                       check=True, capture_output=True)  # fmt: skip
        package = work / "package"
        package.mkdir()
        (package / "ros_gz_bridge_py").symlink_to(tree / "ros_gz_bridge_py")
        yield package
    finally:
        subprocess.run([*git, "worktree", "remove", "--force", str(tree)], check=False,
                       capture_output=True)  # fmt: skip


# ---- the report -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Row:
    kind: str
    direction: str
    size_in: int
    size_out: int
    #: Instructions per message: the C function, the same call from Python, the Python path.
    native: float | None
    native_call: float | None
    python: float
    same_bytes: bool | None


def rows(counted: list[Counted]) -> list[Row]:
    """Per kind and direction, instructions per message (the empty calls taken off)."""
    empty = next(c for c in counted if c.phase.path == "empty")
    per_call = empty.total / empty.phase.messages
    found: dict[tuple[str, str], dict[str, Counted]] = {}
    for c in counted:
        if c.phase.path != "empty":
            found.setdefault((c.phase.kind, c.phase.direction), {})[c.phase.path] = c
    out = []
    for (kind, direction), paths in found.items():
        python = paths["python"]
        native = paths.get("native")
        n = python.phase.messages
        out.append(
            Row(
                kind, direction, python.phase.size_in, python.phase.size_out,
                None if native is None else native.native / n,
                None if native is None else native.total / n - per_call,
                python.total / n - per_call,
                None if native is None else native.phase.same_bytes,
            )
        )  # fmt: skip
    return out


DIRECTIONS = {"gz_to_ros": "Gazebo -> ROS", "ros_to_gz": "ROS -> Gazebo"}


def _count(value: float | None) -> str:
    return "-" if value is None else f"{value:,.0f}"


def _change(now: float | None, before: float | None) -> str:
    if not now or not before:
        return "-"
    return f"{(now - before) / before:+.1%}"


def table(found: list[Row], before: list[Row] | None = None, against: str = "") -> str:
    """The figures per kind and direction; with ``before`` (commit ``against``'s), beside them."""
    earlier = {(r.kind, r.direction): r for r in before or []}
    compared = (
        f" native at {against} | change |" if before is not None else ""
    )  # the C function, before and after
    lines = [
        "| message | direction | bytes in / out | native (the C function) |"
        + compared
        + " native, called from Python | Python path | Python / native | same bytes |",
        "|---|---|---|---|" + ("---|---|" if before is not None else "") + "---|---|---|---|",
    ]
    for r in found:
        ratio = "-" if not r.native else f"{r.python / r.native:.0f}x"
        same = "-" if r.same_bytes is None else ("yes" if r.same_bytes else "**no**")
        then = earlier.get((r.kind, r.direction))
        cells = ""
        if before is not None:
            old = None if then is None else then.native
            cells = f" {_count(old)} | {_change(r.native, old)} |"
        lines.append(
            f"| {r.kind} | {DIRECTIONS[r.direction]} | {r.size_in:,} / {r.size_out:,} "
            f"| **{_count(r.native)}** |{cells} {_count(r.native_call)} | {_count(r.python)} "
            f"| {ratio} | {same} |"
        )
    return "\n".join(lines)


def section(found: list[Row], messages: int, command: str, valgrind: str, *,
            before: list[Row] | None = None, against: str = "") -> str:  # fmt: skip
    compared = (
        f'\n"Native at {against}" is the same count for the package of commit {against}, its '
        "extension built in a temporary worktree and counted in the same run (the same "
        'messages, the same Python and libraries); "change" is this tree\'s against it.\n'
        if before is not None
        else ""
    )
    return f"""## Instructions per message of the native conversion code

Command: `{command}`. {valgrind}; instructions counted by callgrind over {messages:,} messages
of each kind and path in one process (what the benchmark does and why: the docstring of
`benchmarks/instructions.py`). A count does not depend on the machine's load or clock, so two
commits compare in one run each; it is not time (a division or a cache miss costs more cycles
than most instructions, a system call far more), which `costs` and `fleet_cpu_map` measure.

"Native (the C function)" is what a native loop's turn spends converting one message
(`rgb_to_cdr` Gazebo -> ROS, `rgb_to_pb` ROS -> Gazebo); "called from Python" adds the method
call and the result objects, which only tests and this benchmark pay; "Python path" is the
channel's own conversion where the native loop does not run (`FromString`, `to_ros`, the CDR
writer; the light CDR reader, `to_gz`, `SerializeToString`). The messages are those of
`benchmarks/payloads.py`; "same bytes" says both paths wrote the same message.
{compared}
{table(found, before, against)}
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--messages", type=int, default=200, help="messages per phase")
    parser.add_argument("--kinds", nargs="+", default=list(DEFAULT_KINDS), choices=list(KINDS))
    parser.add_argument("--against", default="", help="a commit to count beside this tree")
    parser.add_argument("--driver", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.driver:
        drive(args.messages, args.kinds)
        return 0
    for tool in ("valgrind", "callgrind_annotate"):
        if shutil.which(tool) is None:
            print(f"{tool} is not installed (Debian: apt-get install valgrind)", file=sys.stderr)
            return 1
    version = subprocess.run(
        ["valgrind", "--version"], capture_output=True, text=True, check=False
    ).stdout
    before = None
    with tempfile.TemporaryDirectory(prefix="instructions-") as work:
        found = rows(measure(args.messages, args.kinds, Path(work) / "now"))
        if args.against:
            with package_of(args.against, Path(work)) as package:
                counted = measure(args.messages, args.kinds, Path(work) / "before", package)
            before = rows(counted)
    shown = " ".join(argv if argv is not None else sys.argv[1:])
    command = f".venv/bin/python -m benchmarks.instructions {shown}".strip()
    body = section(found, args.messages, command, version.strip(), before=before,
                   against=args.against)  # fmt: skip
    write_section("instructions", body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
