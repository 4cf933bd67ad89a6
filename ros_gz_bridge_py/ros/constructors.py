"""New rclpy messages without rclpy's ``__init__``, for the Gazebo -> ROS converters.

A generated message ``__init__`` imports each nested message class, reads its keyword
arguments, builds every nested message through its own ``__init__`` and stores each field
through its property setter: an ``Odometry()`` costs ~12.5 µs, a ``TransformStamped()``
~5.4 µs, more than half of converting the message. A converter fills every field it maps
anyway, so all it needs is a message holding the defaults (docs/environment.md §2).

:func:`constructor` compiles, once per class, a function that makes the same object: an
instance of the same class whose slots hold what ``__init__`` would have stored (nested
messages made the same way, a fresh copy of each array and list, the same
``_check_fields``), taken from one message made by rclpy itself (Odometry ~2.1 µs,
TransformStamped ~0.9 µs). Setting fields afterwards goes through rclpy's setters as
before, so what a converter writes, and any error a setter raises, is unchanged. A class
whose defaults are not all values it knows how to copy (or whose result would not equal
``msg_class()``) keeps rclpy's constructor.
"""

from __future__ import annotations

import sys
from array import array
from collections.abc import Callable
from typing import Any

#: Default values stored as they are (immutable).
_IMMUTABLE = (bool, int, float, str, bytes, type(None))


class _UncopiableDefaultError(Exception):
    """A default value :func:`constructor` does not know how to copy."""


def is_message_class(cls: type[Any]) -> bool:
    """True for an rclpy (rosidl-generated) message class."""
    return hasattr(cls, "SLOT_TYPES") and hasattr(cls, "get_fields_and_field_types")


def constructor(msg_class: type[Any]) -> Callable[[], Any]:
    """A function making what ``msg_class()`` makes, faster (see the module docstring), built
    once; the class itself where that cannot be guaranteed."""
    if msg_class not in _CONSTRUCTORS:
        try:
            make = _compile(msg_class)
        except _UncopiableDefaultError:
            make = msg_class
        _CONSTRUCTORS[msg_class] = make if make() == msg_class() else msg_class
    return _CONSTRUCTORS[msg_class]


_CONSTRUCTORS: dict[type[Any], Callable[[], Any]] = {}


def _compile(msg_class: type[Any]) -> Callable[[], Any]:
    if not is_message_class(msg_class):
        raise _UncopiableDefaultError(msg_class)
    template = msg_class()
    namespace: dict[str, Any] = {"_new": object.__new__, "_class": msg_class}
    lines = ["def make():", "    m = _new(_class)"]
    for slot in msg_class.__slots__:
        name = f"_k{len(namespace)}"
        namespace[name] = value = getattr(template, slot)
        lines.append(f"    m.{slot} = {_copy_expression(value, name, namespace)}")
    lines.append("    return m")
    code = compile("\n".join(lines), f"<constructor {msg_class.__name__}>", "exec")
    exec(code, namespace)  # noqa: S102 - the source names only the class's own slots
    make: Callable[[], Any] = namespace["make"]
    return make


def _copy_expression(value: Any, name: str, namespace: dict[str, Any]) -> str:
    """Python making a fresh copy of the default ``value`` (held in ``namespace[name]``)."""
    if isinstance(value, _IMMUTABLE):
        return name
    np = sys.modules.get("numpy")  # an ndarray exists only once numpy is imported
    if np is not None and isinstance(value, np.ndarray):
        return f"{name}.copy()"
    if is_message_class(type(value)):
        namespace[name] = constructor(type(value))
        return f"{name}()"
    if isinstance(value, array) or (
        isinstance(value, list) and all(isinstance(item, _IMMUTABLE) for item in value)
    ):
        return f"{name}[:]"
    if isinstance(value, list) and value and is_message_class(type(value[0])):
        if any(type(item) is not type(value[0]) for item in value):
            raise _UncopiableDefaultError(value)
        namespace[name] = constructor(type(value[0]))
        return f"[{name}() for _ in range({len(value)})]"
    raise _UncopiableDefaultError(value)
