"""benchmarks.fleet_memory's report: libzmq's cost per waiting message, each fleet round,
each flooded round."""

from __future__ import annotations

from benchmarks.fleet_memory import MemoryRound, report
from benchmarks.harness import FlowResult


def test_each_round_says_its_receive_queue_its_memory_and_its_clock() -> None:
    rounds = [
        MemoryRound(
            "1000",
            60.0,
            306.4,
            [210.0, 250.0, 230.0],
            [100.0, 201.0, 120.0],
            0.61,
            4.2,
            55.04,
            36.12,
            50,
        ),
        MemoryRound(
            "",
            60.0,
            217.0,
            [205.0, 207.0, 209.0],
            [98.0, 100.0, 99.0],
            0.70,
            4.8,
            53.0,
            35.0,
            50,
        ),
    ]
    floods = [
        ("", FlowResult(80000, 79565, 19891.0, 900.0, 79400.0, 40.98)),
        ("50", FlowResult(80001, 75967, 18991.0, 950.0, 84100.0, 51.26)),
        ("50", FlowResult(0, 0, 0.0, 0.0, 0.0, None, "bridge did not start")),
    ]
    text = report({"paced": 8992.4, "back to back": 1983.0}, 50, rounds, floods, "command")
    assert "| paced | 8,992 bytes |" in text
    assert "| back to back | 1,983 bytes |" in text
    assert "| 1 | 1000 | 306 | 230 | 250 | 120 | 201 | 55.0% | 36.1 | 61.0% | 4.2 |" in text
    assert (
        "| 2 | 50 (default, planned) | 217 | 207 | 209 | 99 | 100 | 53.0% | 35.0 | 70.0% |" in text
    )
    assert "| 1 | 1000 (default) | 79565/80000 (99.5%) | 41% | 79.4 ms |" in text
    assert "| 2 | 50 | 75967/80001 (95.0%) | 51% | 84.1 ms |" in text
    assert "| 3 | 50 | failed: bridge did not start | | |" in text


def test_a_run_of_floods_alone_still_writes_its_report() -> None:
    """``--rounds 0`` (the flooded topic alone) failed on the fleet part's first round."""
    floods = [("", FlowResult(80000, 80000, 20000.0, 70.0, 24600.0, 35.8))]
    text = report({"paced": 8980.0}, 10, [], floods, "command")
    assert "### The fleet of 10 robots: no round (`--rounds 0`)" in text
    assert "| 1 | 1000 (default) | 80000/80000 (100.0%) | 36% | 24.6 ms |" in text
