"""Write one benchmark's section of BENCHMARKS.md, leaving the other sections as they are.

Each benchmark owns the text between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->``;
sections are kept in the order they were first written, except the one written ``first``
(the headline), which always comes right after the title.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from datetime import UTC, datetime
from pathlib import Path

REPORT = Path(__file__).resolve().parent.parent / "BENCHMARKS.md"
TITLE = "# Benchmarks\n\nWritten by `make bench`; each section says the command that produced it.\n"


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


def write_section(name: str, body: str, *, first: bool = False) -> None:
    """Replace (or append) the section ``name`` of BENCHMARKS.md with ``body``; ``first``
    puts it right after the title."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    block = f"{begin}\n{body.rstrip()}\n\n_Machine: {machine_line()}._\n{end}\n"
    text = REPORT.read_text(encoding="utf-8") if REPORT.exists() else TITLE
    if first:
        if begin in text and end in text:
            head, rest = text.split(begin, 1)
            text = head.rstrip("\n") + "\n\n" + rest.split(end, 1)[1].lstrip("\n")
        rest = text[len(TITLE) :] if text.startswith(TITLE) else text
        text = TITLE + "\n" + block + "\n" + rest.lstrip("\n")
    elif begin in text and end in text:
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = head + block + tail.lstrip("\n")
    else:
        text = text.rstrip("\n") + "\n\n" + block
    REPORT.write_text(text, encoding="utf-8")
    print(f"wrote section {name!r} of {REPORT}", file=sys.stderr)
