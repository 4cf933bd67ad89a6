"""The figures of the headline and the plots, kept between runs in ``benchmarks/results.json``.

A benchmark that feeds the headline stores its flows here under its own name, with the commit,
the time and the load average of its run. The headline and the plots read them back, so a run
of one benchmark (``benchmarks.run --only NAME``) refreshes its own figures and shows the
others from their own, dated, runs.
"""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from benchmarks.harness import FlowResult

RESULTS = Path(__file__).resolve().parent / "results.json"
#: The plots drawn from them, relative to the repository root (BENCHMARKS.md links them so; a report
#: in ``benchmarks/reports/`` through ``report.link``).
SUSTAINED_PNG = "benchmarks/plots/sustained_1080p.png"
COSTS_PNG = "benchmarks/plots/cpu_per_message.png"
FLEET_PNG = "benchmarks/plots/fleet.png"


@dataclass(frozen=True)
class Stored:
    """One benchmark's flows from its last run, by the names it gave them."""

    when: str
    commit: str
    load_before: float
    load_after: float
    flows: dict[str, FlowResult]
    #: Other figures of the run, by name (counters, settings).
    numbers: dict[str, float]

    def flow(self, name: str) -> FlowResult | None:
        return self.flows.get(name)

    def measured(self) -> str:
        """The commit and date of the run, for a figure taken from it."""
        return f"commit {self.commit}, {self.when}"

    def run_line(self) -> str:
        """When, at which commit and under which load the figures were measured."""
        return (
            f"{self.when}, commit {self.commit}, 1-minute load average {self.load_before:.2f} "
            f"before and {self.load_after:.2f} after"
        )


def store(
    name: str,
    flows: dict[str, FlowResult],
    load_before: float,
    numbers: dict[str, float] | None = None,
) -> None:
    """Keep ``flows`` (and ``numbers``) as benchmark ``name``'s figures, replacing its earlier
    ones."""
    commit = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
    ).stdout.strip()
    data = _read()
    data[name] = {
        "when": f"{datetime.now(UTC):%Y-%m-%d %H:%M} UTC",
        "commit": commit or "uncommitted",
        "load_before": round(load_before, 2),
        "load_after": round(os.getloadavg()[0], 2),
        "flows": {key: dataclasses.asdict(flow) for key, flow in flows.items()},
        "numbers": numbers or {},
    }
    RESULTS.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n", encoding="utf-8")


def load(name: str) -> Stored | None:
    """Benchmark ``name``'s stored figures, None if it never stored any."""
    entry = _read().get(name)
    return None if entry is None else stored(entry)


def stored(entry: dict[str, Any]) -> Stored:
    """One benchmark's entry of ``results.json`` as :class:`Stored`."""
    flows = {key: _flow(value) for key, value in entry["flows"].items()}
    return Stored(
        entry["when"],
        entry["commit"],
        entry["load_before"],
        entry["load_after"],
        flows,
        entry.get("numbers", {}),
    )


def _flow(value: dict[str, Any]) -> FlowResult:
    flood = value.get("flood")
    return FlowResult(**{**value, "flood": None if flood is None else _flow(flood)})


def _read() -> dict[str, Any]:
    if not RESULTS.exists():
        return {}
    data: dict[str, Any] = json.loads(RESULTS.read_text(encoding="utf-8"))
    return data
