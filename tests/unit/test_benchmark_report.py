"""How BENCHMARKS.md is put together: the headline first, the other sections where they were,
and what counts as a sustainable 1080p rate."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import report
from benchmarks.harness import FlowResult
from benchmarks.sustained import highest


@pytest.fixture
def report_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "BENCHMARKS.md"
    monkeypatch.setattr(report, "REPORT", path)
    monkeypatch.setattr(report, "machine_line", lambda: "test machine")
    return path


def _sections(text: str) -> list[str]:
    return [
        line.split()[1].split(":")[0] for line in text.splitlines() if line.endswith("begin -->")
    ]


def test_the_headline_goes_first_and_the_others_keep_their_places(report_file: Path) -> None:
    report.write_section("transport", "## T\n")
    report.write_section("images", "## I\n")
    report.write_section("headline", "## H one\n", first=True)
    report.write_section("transport", "## T again\n")
    report.write_section("headline", "## H two\n", first=True)
    report.write_section("memory", "## M\n")

    text = report_file.read_text(encoding="utf-8")
    assert text.startswith(report.TITLE + "\n<!-- headline:begin -->\n## H two\n")
    assert _sections(text) == ["headline", "transport", "images", "memory"]
    assert "H one" not in text
    assert "## T again" in text
    assert "\n\n\n" not in text


def _flow(share: float, p99_ms: float, error: str = "") -> FlowResult:
    return FlowResult(1000, round(share * 1000), 30.0, 1000.0, p99_ms * 1000, None, error)


def test_the_highest_sustainable_rate_is_the_last_of_an_unbroken_run() -> None:
    good, late, short = _flow(1.0, 40), _flow(1.0, 100), _flow(0.98, 40)
    assert highest({30.0: good, 60.0: good, 90.0: late, 120.0: good}) == 60.0
    assert highest({30.0: good, 60.0: short}) == 30.0
    assert highest({60.0: good, 30.0: good}) == 60.0
    assert highest({30.0: _flow(1.0, 40, "bridge did not start")}) is None
