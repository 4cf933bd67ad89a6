"""A short soak in the suite (``make soak`` runs the long one and writes SOAK.md).

45 s of ``testing/soak.py``: mixed traffic both ways, a service called five times a second,
the Gazebo Odometry publisher killed and restarted every 20 s, ROS subscriptions made and
destroyed every 2 s, malformed discovery datagrams and a rogue publisher's garbage every 15 s.
The bounds below are what "survives" means here, with room for a busy 2-core machine; the
figures themselves are in the report of ``make soak``.
"""

from __future__ import annotations

import pytest

from testing.gzpeer import require_peer
from testing.soak import Soak

pytestmark = [pytest.mark.peer, pytest.mark.ros, pytest.mark.slow]

SECONDS = 45.0


def test_the_bridge_survives_a_short_soak() -> None:
    require_peer()
    figures = Soak(SECONDS).run()
    ros = figures.ros
    assert figures.bridge_alive, "the bridge died during the soak"
    assert figures.bridge_exit == 0, figures.status_table
    assert figures.restarts >= 2
    assert figures.fuzz_datagrams > 0
    assert figures.fuzz_frames > 0
    # Every service call answered once (but those still waiting when the run stopped).
    assert int(ros["answered"]) + int(ros["waiting"]) == int(ros["calls"]), ros
    assert int(ros["succeeded"]) > 0, ros
    # Traffic flowed both ways, and Odometry came back after every restart within seconds.
    assert int(ros["clock"]) > 0.7 * 100 * (SECONDS - 10), ros
    assert figures.commands_at_gazebo > 0.7 * int(ros["cmd_sent"]) - 500, ros
    gaps = [seconds for _, seconds in ros["odom_gaps"]]
    assert max(gaps, default=0.0) < 5.0, gaps
    # Memory does not climb (after the first 10 s of warm-up).
    settled = [rss for t, rss, _ in figures.samples if t >= 10]
    assert settled[-1] - min(settled) < 40, figures.samples
