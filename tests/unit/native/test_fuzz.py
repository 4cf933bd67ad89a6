"""The native transcoder under libFuzzer, with AddressSanitizer and UndefinedBehaviorSanitizer,
then with MemorySanitizer.

The target (fuzz/transcode_fuzz.c) links transcode.c directly, with every compiled pair's
program from a header generated here (tools/native_fuzz_programs.py). It is built with
clang-14 into ``.build/fuzz/<sanitizer>-<hash>/``, once per hash of its sources, programs and
flags; the builds share ``FUZZ_SECONDS`` (60 by default; ``make fuzz`` and ``make soak`` run
it longer). The corpus is kept in ``.build/fuzz/corpus`` between runs; inputs that crash are
written to ``.build/fuzz/artifacts/``, and every later run tries them first. Without clang-14
(``tools/setup_fuzz.sh`` installs it) the test skips, and fails under CI=true.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
BUILD = ROOT / ".build" / "fuzz"
NATIVE = ROOT / "ros_gz_bridge_py" / "native"
SOURCES = (ROOT / "fuzz" / "transcode_fuzz.c", NATIVE / "transcode.c", NATIVE / "transcode.h")
CLANG = "clang-14"
FLAGS = ("-g", "-O1", "-fno-sanitize-recover=all", "-std=gnu11", "-Wall", "-Wextra")
#: The builds, and each one's share of the fuzzing time: AddressSanitizer with
#: UndefinedBehaviorSanitizer, and MemorySanitizer, which alone sees a read of memory never
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


def _generate(out: Path) -> None:
    subprocess.run(
        [sys.executable, "-m", "tools.native_fuzz_programs", str(out)],
        check=True, cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip


def build(clang: str, sanitizer: str) -> tuple[Path, Path]:
    """The fuzz target and its seed corpus, built unless this hash was built already."""
    flags = (*FLAGS, *SANITIZERS[sanitizer][0])
    BUILD.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(dir=BUILD, prefix="tmp-"))
    try:
        _generate(work)
        digest = hashlib.sha256((work / "programs.h").read_bytes())
        for source in SOURCES:
            digest.update(source.read_bytes())
        digest.update(" ".join((CLANG, *flags)).encode())
        target = BUILD / f"{sanitizer}-{digest.hexdigest()[:16]}"
        if not (target / "transcode_fuzz").exists():
            result = subprocess.run(
                [clang, *flags, "-I", str(work), "-I", str(NATIVE), str(SOURCES[0]),
                 str(SOURCES[1]), "-o", str(work / "transcode_fuzz"), "-lm"],
                check=False, capture_output=True, text=True,
            )  # fmt: skip
            assert result.returncode == 0, f"building the fuzz target failed:\n{result.stderr}"
            with contextlib.suppress(OSError):  # built meanwhile by another run
                work.rename(target)
        return target / "transcode_fuzz", target / "corpus"
    finally:
        shutil.rmtree(work, ignore_errors=True)


@pytest.mark.slow
@pytest.mark.parametrize("sanitizer", SANITIZERS)
def test_transcoder_survives_fuzzing(sanitizer: str) -> None:
    binary, seeds = build(require_clang(), sanitizer)
    seconds = max(1, round(fuzz_seconds() * SANITIZERS[sanitizer][1]))
    corpus = BUILD / "corpus"
    artifacts = BUILD / "artifacts"
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
