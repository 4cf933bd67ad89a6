"""benchmarks.fleet_clock reads the /clock row of the bridge's own status table."""

from __future__ import annotations

from benchmarks.fleet_clock import ClockRound, _counters, report
from ros_gz_bridge_py.core.status import ChannelStatus, format_table


def _clock_status(received: int, published: int, errors: int, dropped: int) -> ChannelStatus:
    return ChannelStatus(
        direction="GZ->ROS", ros_name="/clock", gz_name="/clock",
        ros_type="rosgraph_msgs/msg/Clock", gz_type="gz.msgs.Clock", state="active",
        received=received, published=published, errors=errors, dropped=dropped, rate=1000.0,
        new_problems=0,
    )  # fmt: skip


def test_the_newest_clock_row_gives_in_out_and_dropped_not_errors() -> None:
    older = format_table([_clock_status(3935, 3935, 0, 0)]).splitlines()
    newest = format_table([_clock_status(24939, 24930, 7, 2)]).splitlines()
    assert _counters(older + newest) == (24939, 24930, 2)


def test_the_report_says_what_the_bridge_lost_and_what_the_subscriber_got() -> None:
    rounds = [ClockRound(20.0, 20000, 19990, 4, 15000, 3.5)]
    text = report(50, rounds, "command")
    assert "| 1 | 20000 (100.0%) | 19990 (100.0%) | 4 | 15000 (75.0%) | 3.5 |" in text
    assert "Lost in the bridge over all rounds: 14 messages" in text
