"""Which pairs the native path carries (``native/channel.py``), as the docs count them."""

from __future__ import annotations

import re
from pathlib import Path

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.native.channel import expressible

CONFIGURATION = Path(__file__).resolve().parents[3] / "docs" / "configuration.md"


def test_the_docs_count_the_pairs_that_compile_each_way() -> None:
    """docs/configuration.md said 40 towards ROS when 44 compiled."""
    to_ros, to_gz = expressible(default_registry().pairs)
    compiled = [sum(not why for why in reasons.values()) for reasons in (to_ros, to_gz)]
    text = " ".join(CONFIGURATION.read_text().split())
    stated = [int(n) for n in re.findall(r"(\d+) pairs compile", text)]
    assert stated == compiled, "docs/configuration.md, 'The native data plane'"
