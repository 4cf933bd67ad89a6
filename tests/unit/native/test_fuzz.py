"""The native transcoders under libFuzzer, with AddressSanitizer and UndefinedBehaviorSanitizer,
then with MemorySanitizer.

Three targets: fuzz/transcode_fuzz.c links the transcoder (transcode.c, pb_read.c,
transcode_load.c: Gazebo -> ROS) with every compiled pair's program, fuzz/encode_fuzz.c links
the encoder (encode.c, encode_write.c, encode_load.c: ROS -> Gazebo) with every compiled pair's
encoder, each from a header generated here (tools/native_fuzz_programs.py, which writes
codes.h beside it), and fuzz/loop_fuzz.c links the whole extension and embeds this Python: a
channel's pump of either direction (pump.c, pump_loop.c; ros_pump.c, ros_pump_loop.c) taking
the messages of the input from fake ZeroMQ and rcl functions, a Gazebo -> ROS pump taught by the
real Python reader (loop_fuzz_host.py). Each is built with clang-14 into
``.build/fuzz/<target>-<sanitizer>-<hash>/``, once per hash of its sources, headers and flags;
the builds share ``FUZZ_SECONDS`` (60 by default; ``make fuzz`` and ``make soak`` run it
longer). Each target's corpus is kept in ``.build/fuzz/`` between runs (``corpus``,
``encode-corpus``, ``loop-corpus``); inputs that crash are written beside it (``artifacts/``,
``encode-artifacts/``, ``loop-artifacts/``), and every later run tries them first. Without
clang-14 (``tools/setup_fuzz.sh`` installs it) the test skips, and fails under CI=true.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
BUILD = ROOT / ".build" / "fuzz"
NATIVE = ROOT / "ros_gz_bridge_py" / "native"
CLANG = "clang-14"
FLAGS = ("-g", "-O1", "-fno-sanitize-recover=all", "-std=gnu11", "-Wall", "-Wextra")
#: The builds of each target, and each one's share of the target's time: AddressSanitizer
#: with UndefinedBehaviorSanitizer, and MemorySanitizer, which alone sees a read of memory never
#: written (it found one, in the header lookup of a program whose path misled it).
SANITIZERS = {
    "asan-ubsan": (("-fsanitize=fuzzer,address,undefined",), 2 / 3),
    "msan": (("-fsanitize=fuzzer,memory", "-fsanitize-memory-track-origins"), 1 / 3),
}
#: What the sanitizers and libFuzzer print when they stop on a finding.
FINDINGS = (
    "ERROR: AddressSanitizer", "WARNING: MemorySanitizer", "runtime error:", "ERROR: libFuzzer",
    "SUMMARY: ",
)  # fmt: skip


@dataclass(frozen=True)
class Target:
    """A fuzz target: its source, the native files it links or includes, the header
    tools/native_fuzz_programs.py writes for it, where its corpus and findings are kept, and
    its share of the fuzzing time; ``python``: it embeds Python (built with AddressSanitizer
    only: MemorySanitizer would need an instrumented libpython)."""

    source: str
    native: tuple[str, ...]
    header: str
    corpus: str
    artifacts: str
    share: float
    python: bool = False
    #: Its other files in fuzz/ (C files and headers).
    parts: tuple[str, ...] = ()

    def sources(self) -> list[Path]:
        python = [Path(__file__).with_name("loop_fuzz_host.py")] if self.python else []
        fuzz = [ROOT / "fuzz" / name for name in (self.source, *self.parts)]
        return [*fuzz, *(NATIVE / name for name in self.native), *python]

    def sanitizers(self) -> list[str]:
        return ["asan-ubsan"] if self.python else list(SANITIZERS)

    def flags(self) -> tuple[str, ...]:
        """What embedding Python adds: its headers and library, and where the target finds
        this venv's interpreter and the repository."""
        if not self.python:
            return ()
        include, libdir = sysconfig.get_path("include"), sysconfig.get_config_var("LIBDIR")
        version = sysconfig.get_config_var("LDVERSION")
        return (
            f"-I{include}", f'-DFUZZ_PYTHON="{sys.executable}"', f'-DFUZZ_ROOT="{ROOT}"',
            f"-L{libdir}", f"-Wl,-rpath,{libdir}", f"-lpython{version}",
        )  # fmt: skip


TARGETS = {
    "transcode": Target(
        "transcode_fuzz.c",
        ("transcode.c", "pb_read.c", "transcode_load.c", "transcode.h", "transcode_ops.h",
         "wire.h", "codes.py"),
        "programs.h", "corpus", "artifacts", 3 / 8,
    ),
    "encode": Target(
        "encode_fuzz.c",
        ("encode.c", "encode_write.c", "encode_load.c", "encode.h", "encode_ops.h",
         "transcode.h", "wire.h", "codes.py"),
        "encoders.h", "encode-corpus", "encode-artifacts", 3 / 8,
    ),
    "loop": Target(
        "loop_fuzz.c",
        ("_native.c", "encode.c", "encode_load.c", "encode_write.c", "loop.c", "pb_read.c",
         "pump.c", "pump_loop.c", "pump_share.c", "ros_pump.c", "ros_pump_loop.c", "transcode.c",
         "transcode_load.c", "transcoders.c", "_native.h", "encode.h", "encode_ops.h",
         "transcode.h", "transcode_ops.h", "wire.h", "codes.py"),
        "programs.h", "loop-corpus", "loop-artifacts", 1 / 4, python=True,
        parts=("loop_fuzz.h", "loop_fuzz_pump.c", "loop_fuzz_reference.c", "loop_fuzz_ros_pump.c",
               "loop_fuzz_zmq.c"),
    ),
}  # fmt: skip


def fuzz_seconds() -> int:
    return int(os.environ.get("FUZZ_SECONDS", "60"))


def require_clang() -> str:
    """clang-14's path; skips without it, fails instead under CI=true."""
    clang = shutil.which(CLANG)
    if clang is not None:
        return clang
    reason = f"{CLANG} missing; run tools/setup_fuzz.sh (as root) to install it"
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(reason)
    pytest.skip(reason)


def _generate(out: Path, name: str) -> None:
    subprocess.run(
        [sys.executable, "-m", "tools.native_fuzz_programs", str(out), "--target", name],
        check=True, cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip


def build(clang: str, name: str, sanitizer: str) -> tuple[Path, Path]:
    """Target ``name``'s binary and its seed corpus, built unless this hash was built already."""
    flags = (*FLAGS, *SANITIZERS[sanitizer][0], *TARGETS[name].flags())
    sources = TARGETS[name].sources()
    binary = f"{name}_fuzz"
    BUILD.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(dir=BUILD, prefix="tmp-"))
    try:
        _generate(work, name)
        digest = hashlib.sha256((work / TARGETS[name].header).read_bytes())
        for header in sorted(work.glob("*.h")):  # the loop target's encoders.h too
            digest.update(header.read_bytes())
        for source in sources:
            digest.update(source.read_bytes())
        digest.update(" ".join((CLANG, *flags)).encode())
        target = BUILD / f"{name}-{sanitizer}-{digest.hexdigest()[:16]}"
        if not (target / binary).exists():
            compiled = [str(source) for source in sources if source.suffix == ".c"]
            result = subprocess.run(
                [clang, *flags, "-I", str(work), "-I", str(NATIVE), *compiled,
                 "-o", str(work / binary), "-lm"],
                check=False, capture_output=True, text=True,
            )  # fmt: skip
            assert result.returncode == 0, f"building the fuzz target failed:\n{result.stderr}"
            with contextlib.suppress(OSError):  # built meanwhile by another run
                work.rename(target)
        return target / binary, target / "corpus"
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _runs() -> list[tuple[str, str]]:
    return [(name, s) for name, target in TARGETS.items() for s in target.sanitizers()]


def _share(name: str, sanitizer: str) -> float:
    """The run's share of FUZZ_SECONDS: its target's, split between the target's sanitizers."""
    target = TARGETS[name]
    weights = {s: SANITIZERS[s][1] for s in target.sanitizers()}
    return target.share * weights[sanitizer] / sum(weights.values())


def test_shares_sum_to_the_budget() -> None:
    assert abs(sum(_share(name, sanitizer) for name, sanitizer in _runs()) - 1) < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize(("name", "sanitizer"), _runs())
def test_target_survives_fuzzing(name: str, sanitizer: str) -> None:
    binary, seeds = build(require_clang(), name, sanitizer)
    share = _share(name, sanitizer)
    seconds = max(1, round(fuzz_seconds() * share))
    corpus = BUILD / TARGETS[name].corpus
    artifacts = BUILD / TARGETS[name].artifacts
    corpus.mkdir(exist_ok=True)
    artifacts.mkdir(exist_ok=True)
    result = subprocess.run(
        [str(binary), f"-max_total_time={seconds}", "-rss_limit_mb=2048", "-timeout=30",
         "-print_final_stats=1", f"-artifact_prefix={artifacts}/{sanitizer}-", str(corpus),
         str(seeds), str(artifacts)],
        check=False, capture_output=True, text=True, timeout=seconds + 600,
    )  # fmt: skip
    tail = "\n".join(result.stderr.splitlines()[-60:])
    found = [line for line in result.stderr.splitlines() if line.startswith(FINDINGS)]
    assert result.returncode == 0, f"the fuzzer stopped ({result.returncode}):\n{tail}"
    assert not found, f"sanitizer findings:\n{tail}"
    runs = [line for line in result.stderr.splitlines() if "number_of_executed_units" in line]
    assert runs, f"no statistics printed:\n{tail}"
    assert int(runs[0].split(":")[-1]) > 0
