"""ROS name expansion used for expand_gz_topic_names."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import expand_topic_name
from ros_gz_bridge_py.errors import ConfigError


@pytest.mark.parametrize(
    ("name", "namespace", "expected"),
    [
        ("scan", "/robot1", "/robot1/scan"),
        ("scan", "/", "/scan"),
        ("scan", "", "/scan"),
        ("scan", "robot1", "/robot1/scan"),
        ("scan", "/a/b/", "/a/b/scan"),
        ("model/car/odom", "/robot1", "/robot1/model/car/odom"),
        ("/clock", "/robot1", "/clock"),
        ("~/status", "/robot1", "/robot1/bridge/status"),
        ("~/status", "/", "/bridge/status"),
        ("~", "/robot1", "/robot1/bridge"),
        ("{node}/x", "/ns", "/ns/bridge/x"),
        ("{ns}/x", "/ns", "/ns/x"),
        ("{namespace}/x", "/", "/x"),
    ],
)
def test_expand(name: str, namespace: str, expected: str) -> None:
    assert expand_topic_name(name, namespace, "bridge") == expected


@pytest.mark.parametrize("name", ["", "~x"])
def test_invalid(name: str) -> None:
    with pytest.raises(ConfigError):
        expand_topic_name(name, "/ns", "bridge")
