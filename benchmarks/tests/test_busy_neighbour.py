"""The 20 kHz goal's lines, from a small stored run: the share is of what was offered (an rclpy
publisher beside a busy loop sends less than it is asked to), the verdict follows it, and the
bridge's counters say where the rest was lost."""

from __future__ import annotations

from typing import Any

from benchmarks import busy_neighbour, headline
from benchmarks.results import Stored, stored


def flow(sent: int, received: int) -> dict[str, Any]:
    return {
        "sent": sent,
        "received": received,
        "rate": 0.0,
        "median_us": 100.0,
        "p99_us": 2000.0,
        "cpu": 50.0,
        "error": "",
    }


def run(busy_received: int, ceiling_sent: int) -> Stored:
    """One round per condition of 1 s at 20 kHz; beside the busy loop the bridge received all
    20000, dropped 500 in its queue and published the rest."""
    return stored(
        {
            "commit": "abc1234",
            "when": "2026-11-30 04:00 UTC",
            "load_before": 0.2,
            "load_after": 1.5,
            "flows": {
                "bridge.quiet.0": flow(20000, 20000),
                "ceiling.quiet.0": flow(20000, 20000),
                "bridge.busy.0": flow(20000, busy_received),
                "ceiling.busy.0": flow(ceiling_sent, ceiling_sent),
            },
            "numbers": {
                "seconds": 1.0,
                "bridge.quiet.0.in": 20000,
                "bridge.quiet.0.out": 20000,
                "bridge.quiet.0.dropped": 0,
                "bridge.busy.0.in": 19500,
                "bridge.busy.0.out": 19500,
                "bridge.busy.0.dropped": 500,
            },
        }
    )


def test_the_verdict_follows_the_share_of_what_was_offered() -> None:
    quiet, busy = busy_neighbour.goal_lines(run(19500, 13000))

    assert quiet.startswith(
        "- Odometry offered at 20 kHz through one process, quiet: 100.0% delivered (rounds "
        "100.0%; goal >= 95%): **met**"
    )
    assert busy.startswith(
        "- Odometry offered at 20 kHz through one process, beside a busy loop: 97.5% delivered"
    )
    assert "**met**" in busy
    # The ceiling delivered all it sent, but sent only 65% of the offered rate.
    assert "rclpy publisher, asked for the same rate, sent 65.0% of it and delivered 65.0%" in busy


def test_a_miss_says_by_how_much_and_where_the_messages_went() -> None:
    _quiet, busy = busy_neighbour.goal_lines(run(15000, 20000))

    assert "75.0% delivered (rounds 75.0%; goal >= 95%): **missed** by 20.0 points" in busy
    assert (
        "of 20000 sent the bridge received 20000 (100.0%), dropped 500 in its queue and "
        "published 19500; the subscriber took 15000 of those (76.9%)"
    ) in busy


def test_the_headline_shows_the_goal_or_says_it_was_not_measured() -> None:
    shown = headline.section(None, None, None, "", busy_run=run(15000, 20000))

    assert "One topic at 20 kHz (issue 36) (commit abc1234, 2026-11-30 04:00 UTC)" in shown
    assert "beside a busy loop: 75.0% delivered" in shown
    assert "- `busy_neighbour`: 2026-11-30 04:00 UTC, commit abc1234" in shown
    assert "- not measured yet (`benchmarks.busy_neighbour`)" in headline.section(
        None, None, None, ""
    )
