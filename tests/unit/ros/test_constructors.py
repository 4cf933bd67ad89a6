"""The compiled message constructors make what rclpy's constructors make, slot for slot.

Converters set fields through rclpy's own setters after construction, so a message made by
:func:`constructor` that holds, in every slot and nested slot, a value of the same type equal
to the one ``msg_class()`` holds, and shares no mutable value with any other message, converts
and serializes exactly as before, errors included.
"""

from __future__ import annotations

from array import array
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import Point, TransformStamped
from nav_msgs.msg import Odometry
from rclpy.serialization import deserialize_message, serialize_message
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.ros.constructors import constructor, is_message_class
from tests.ros_values import filled


def reachable(classes: set[type[Any]]) -> list[type[Any]]:
    """``classes`` and every message class nested in them, by name."""
    seen: set[type[Any]] = set()
    todo = list(classes)
    while todo:
        cls = todo.pop()
        if cls in seen:
            continue
        seen.add(cls)
        template = cls()
        for slot in cls.__slots__:
            value = getattr(template, slot)
            items = value if isinstance(value, list) else [value]
            todo += [type(item) for item in items if is_message_class(type(item))]
    return sorted(seen, key=lambda cls: cls.__module__ + cls.__name__)


CLASSES = reachable({pair.ros_class for pair in default_registry().pairs})


def assert_same_slots(ours: Any, theirs: Any, path: str) -> None:
    """Same type, equal values, and no mutable value of ``ours`` is one of ``theirs``."""
    assert type(ours) is type(theirs), path
    if is_message_class(type(ours)):
        assert ours is not theirs, path
        for slot in type(ours).__slots__:
            assert_same_slots(getattr(ours, slot), getattr(theirs, slot), f"{path}.{slot}")
    elif isinstance(ours, np.ndarray):
        assert ours is not theirs, path
        assert ours.dtype == theirs.dtype, path
        assert np.array_equal(ours, theirs), path
    elif isinstance(ours, list | array):
        assert ours is not theirs, path
        assert len(ours) == len(theirs), path
        for index, (mine, other) in enumerate(zip(ours, theirs, strict=True)):
            assert_same_slots(mine, other, f"{path}[{index}]")
    else:
        assert ours == theirs, path


@pytest.mark.parametrize("msg_class", CLASSES, ids=lambda cls: cls.__name__)
def test_a_constructed_message_is_rclpys_slot_for_slot(msg_class: type[Any]) -> None:
    make = constructor(msg_class)
    first, second = make(), make()
    assert_same_slots(first, msg_class(), msg_class.__name__)
    assert_same_slots(first, second, msg_class.__name__)  # no mutable part shared
    assert first == msg_class()


@pytest.mark.parametrize(
    "msg_class", [Odometry, TransformStamped, TFMessage, Imu, JointState, Clock, Point]
)
def test_the_high_rate_types_are_compiled(msg_class: type[Any]) -> None:
    assert constructor(msg_class) is not msg_class


@pytest.mark.parametrize("msg_class", [Odometry, Imu, JointState], ids=lambda cls: cls.__name__)
def test_filling_a_constructed_message_serializes_as_filling_rclpys(msg_class: type[Any]) -> None:
    """Every field set through the setters, as a converter does, on both kinds of message."""
    values, same_values = filled(msg_class), filled(msg_class)
    ours, theirs = constructor(msg_class)(), msg_class()
    for name in msg_class.get_fields_and_field_types():
        setattr(ours, name, getattr(values, name))
        setattr(theirs, name, getattr(same_values, name))
    assert_same_slots(ours, theirs, msg_class.__name__)
    # rclpy leaves padding bytes uninitialised: compare what it reads back.
    assert deserialize_message(serialize_message(ours), msg_class) == values


def test_a_class_that_is_not_a_message_keeps_its_own_constructor() -> None:
    assert constructor(dict) is dict
