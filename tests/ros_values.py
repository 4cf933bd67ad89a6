"""ROS messages filled with distinctive values, for tests that compare two ways of handling one.

Every field gets a value no other field of the message has (a counter runs through the whole
tree), sequences hold several elements and nested messages are filled too, so a swapped,
dropped or misaligned field shows.
"""

from __future__ import annotations

import importlib
import itertools
from typing import Any

_INT_RANGES = {
    "int8": 127,
    "uint8": 255,
    "char": 255,
    "int16": 30_000,
    "uint16": 60_000,
    "int32": 2_000_000_000,
    "uint32": 4_000_000_000,
    "int64": 2**62,
    "uint64": 2**63,
}


def _value(slot: Any, counter: itertools.count[int]) -> Any:
    kind = type(slot).__name__
    n = next(counter)
    if kind == "BasicType":
        name = slot.typename
        if name == "boolean":
            return n % 2 == 1
        if name == "octet":
            return bytes([n % 256])
        if name in {"float", "double"}:
            return n * 1.5 + 0.25
        return (n * 7 + 3) % _INT_RANGES[name]
    if kind in {"UnboundedString", "BoundedString"}:
        return f"s{n}"[: getattr(slot, "maximum_size", 99) or 99]
    if kind == "NamespacedType":
        module = importlib.import_module(".".join(slot.namespaces))
        return filled(getattr(module, slot.name), counter)
    if kind == "Array":
        return [_value(slot.value_type, counter) for _ in range(slot.size)]
    if kind in {"UnboundedSequence", "BoundedSequence"}:
        size = min(3, getattr(slot, "maximum_size", 3) or 3)
        values = [_value(slot.value_type, counter) for _ in range(size)]
        octets = getattr(slot.value_type, "typename", "") == "octet"
        return b"".join(values) if octets else values
    raise AssertionError(kind)


def filled(msg_class: type[Any], counter: itertools.count[int] | None = None) -> Any:
    counter = counter if counter is not None else itertools.count(1)
    msg = msg_class()
    fields = msg_class.get_fields_and_field_types()
    for name, slot in zip(fields, msg_class.SLOT_TYPES, strict=True):
        setattr(msg, name, _value(slot, counter))
    return msg
