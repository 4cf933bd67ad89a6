"""How the reports are put together: the headline atop BENCHMARKS.md, each other on its own page,
what counts as a sustainable 1080p rate, and the bridge's CPU split by thread."""

from __future__ import annotations

import dataclasses
import os
import threading
import time
from pathlib import Path

import pytest

from benchmarks import report, results
from benchmarks.costs import split_text, thread_split_ms
from benchmarks.harness import FlowResult, thread_group_seconds
from benchmarks.sustained import highest


@pytest.fixture
def report_files(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A repository of its own: BENCHMARKS.md and ``benchmarks/reports/`` under ``tmp_path``."""
    monkeypatch.setattr(report, "ROOT", tmp_path)
    monkeypatch.setattr(report, "INDEX", tmp_path / "BENCHMARKS.md")
    monkeypatch.setattr(report, "REPORTS", tmp_path / "benchmarks" / "reports")
    monkeypatch.setattr(report, "machine_line", lambda: "test machine")
    return tmp_path


def test_each_report_has_its_own_page_rewritten_whole(report_files: Path) -> None:
    report.write_section("transport", "## T\n")
    report.write_section("images", "## I\n")
    report.write_section("transport", "## T again\n")

    pages = report_files / "benchmarks" / "reports"
    assert sorted(path.name for path in pages.iterdir()) == ["images.md", "transport.md"]
    assert (pages / "transport.md").read_text(encoding="utf-8") == (
        "## T again\n\n_Machine: test machine._\n"
    )
    assert not (report_files / "BENCHMARKS.md").exists()


def test_the_headline_goes_first_and_the_index_below_it_is_kept(report_files: Path) -> None:
    index = report_files / "BENCHMARKS.md"
    index.write_text(report.TITLE + "\n## Index\n\n- [T](benchmarks/reports/transport.md)\n")
    report.write_section("headline", "## H one\n", first=True)
    report.write_section("headline", "## H two\n", first=True)

    text = index.read_text(encoding="utf-8")
    assert text.startswith(report.TITLE + "\n<!-- headline:begin -->\n## H two\n")
    assert text.endswith(
        "<!-- headline:end -->\n\n## Index\n\n- [T](benchmarks/reports/transport.md)\n"
    )
    assert "H one" not in text
    assert "\n\n\n" not in text


def test_a_report_links_a_plot_from_its_own_folder() -> None:
    assert report.link("benchmarks/plots/fleet.png") == "../plots/fleet.png"
    assert (report.REPORTS / report.link(results.FLEET_PNG)).resolve() == (
        report.ROOT / results.FLEET_PNG
    )


def _flow(share: float, p99_ms: float, error: str = "") -> FlowResult:
    return FlowResult(1000, round(share * 1000), 30.0, 1000.0, p99_ms * 1000, None, error)


def test_the_highest_sustainable_rate_is_the_last_of_an_unbroken_run() -> None:
    good, late, short = _flow(1.0, 40), _flow(1.0, 100), _flow(0.98, 40)
    assert highest({30.0: good, 60.0: good, 90.0: late, 120.0: good}) == 60.0
    assert highest({30.0: good, 60.0: short}) == 30.0
    assert highest({60.0: good, 30.0: good}) == 60.0
    assert highest({30.0: _flow(1.0, 40, "bridge did not start")}) is None


def _burn(seconds: float) -> None:
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


def test_thread_cpu_is_grouped_by_the_names_libzmq_and_fast_dds_give_their_threads() -> None:
    burnt, read = threading.Event(), threading.Event()

    def named_burner() -> None:
        tid = threading.get_native_id()
        # named as libzmq names the threads of a numbered context (the bulk path's)
        Path(f"/proc/self/task/{tid}/comm").write_text("6/ZMQbg/IO/9", encoding="utf-8")
        _burn(0.3)
        burnt.set()
        read.wait(10)  # a thread's run time is read while it exists

    before = thread_group_seconds(os.getpid())
    thread = threading.Thread(target=named_burner)
    thread.start()
    _burn(0.2)  # this thread keeps the process name: Python
    assert burnt.wait(10)
    after = thread_group_seconds(os.getpid())
    read.set()
    thread.join()
    grown = {group: after[group] - before[group] for group in before}
    assert set(grown) == {"Python", "libzmq I/O", "Fast DDS"}
    assert grown["libzmq I/O"] >= 0.25
    assert grown["Python"] >= 0.15


def test_the_split_is_per_delivered_message_and_survives_the_results_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    threads = {"Python": 20.0, "libzmq I/O": 1.5, "Fast DDS": 0.5}
    flow = dataclasses.replace(_flow(0.5, 1), bridge_threads=threads)  # half delivered
    split = thread_split_ms(1000.0, flow)
    assert split == pytest.approx({"Python": 0.4, "libzmq I/O": 0.03, "Fast DDS": 0.01})
    assert split_text(split) == "0.400 / 0.030 / 0.010"
    assert thread_split_ms(1000.0, _flow(1.0, 1)) is None  # not measured: no split

    monkeypatch.setattr(results, "RESULTS", tmp_path / "results.json")
    results.store("costs", {"row": flow}, load_before=0.5)
    stored = results.load("costs")
    assert stored is not None
    assert stored.flows["row"].bridge_threads == threads
