"""Write one benchmark's report, leaving the others as they are.

Each benchmark owns a page of its own, ``benchmarks/reports/NAME.md``, rewritten whole on each
run. The headline is the exception: it is written ``first``, at the top of BENCHMARKS.md between
``<!-- headline:begin -->`` and ``<!-- headline:end -->``, right after the title and before the
index of the reports, which is written by hand and kept as it is.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
INDEX = ROOT / "BENCHMARKS.md"
REPORTS = ROOT / "benchmarks" / "reports"
TITLE = "# Benchmarks\n\nWritten by `make bench`; each report says the command that produced it.\n"


def machine_line() -> str:
    """One line naming the machine, so numbers are read against the hardware they came from."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            for line in info:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    commit = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
    ).stdout.strip()
    return (
        f"{os.cpu_count()} cores, {cpu}; Python {platform.python_version()}; "
        f"commit {commit or 'uncommitted'}; {datetime.now(UTC):%Y-%m-%d %H:%M} UTC"
    )


def report_path(name: str) -> Path:
    """The page of the report ``name``."""
    return REPORTS / f"{name}.md"


def link(path: str) -> str:
    """``path`` (relative to the repository root, as ``benchmarks.results`` names the plots) as a
    report's page links it."""
    return os.path.relpath(ROOT / path, REPORTS)


def write_section(name: str, body: str, *, first: bool = False) -> None:
    """Write ``body`` as the report ``name``: its own page, or with ``first`` (the headline) the
    top of BENCHMARKS.md, above the index."""
    machine = f"_Machine: {machine_line()}._\n"
    if not first:
        path = report_path(name)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"{body.rstrip()}\n\n{machine}", encoding="utf-8")
        print(f"wrote the report {name!r}: {path}", file=sys.stderr)
        return
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    block = f"{begin}\n{body.rstrip()}\n\n{machine}{end}\n"
    text = INDEX.read_text(encoding="utf-8") if INDEX.exists() else TITLE
    if begin in text and end in text:
        head, rest = text.split(begin, 1)
        text = head.rstrip("\n") + "\n\n" + rest.split(end, 1)[1].lstrip("\n")
    rest = text[len(TITLE) :] if text.startswith(TITLE) else text
    text = TITLE + "\n" + block + "\n" + rest.lstrip("\n")
    INDEX.write_text(text.rstrip("\n") + "\n", encoding="utf-8")
    print(f"wrote section {name!r} of {INDEX}", file=sys.stderr)
