"""The one rule that turns an environment switch off."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.switches import switched_off

NAME = "ROS_GZ_BRIDGE_SOMETHING"


@pytest.mark.parametrize("value", ["off", "OFF", " off ", "0", "false", "False", "no"])
def test_off_values(value: str) -> None:
    assert switched_off(NAME, {NAME: value})


@pytest.mark.parametrize("value", ["", "on", "1", "true", "yes", "offf", "single"])
def test_anything_else_leaves_the_default_on(value: str) -> None:
    assert not switched_off(NAME, {NAME: value})


def test_unset_is_on() -> None:
    assert not switched_off(NAME, {})
