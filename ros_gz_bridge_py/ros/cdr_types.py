"""What the CDR reader and writer know of rosidl types: wire sizes, struct codes, field lists.

Classic little-endian CDR (docs/cdr.md §1-§3) (XCDR1, the encapsulation rmw_fastrtps writes):
after the 4-byte encapsulation header every value is aligned to its own size, counted from the
end of the header; strings are a ``uint32`` length that includes the terminating NUL, then the
bytes and the NUL; sequences a ``uint32`` count, then the elements; a message with no field
carries one ``uint8``. The types are read from rclpy's own description of each message class
(``get_fields_and_field_types`` and ``SLOT_TYPES``).
"""

from __future__ import annotations

import importlib
from typing import Any

#: The encapsulation header of classic little-endian CDR, and where the body starts.
CDR_LE_HEADER = b"\x00\x01\x00\x00"
BODY = 4
#: rosidl basic type -> (size, struct code).
BASIC: dict[str, tuple[int, str]] = {
    "boolean": (1, "?"),
    "octet": (1, "c"),
    "char": (1, "B"),
    "uint8": (1, "B"),
    "int8": (1, "b"),
    "int16": (2, "h"),
    "uint16": (2, "H"),
    "int32": (4, "i"),
    "uint32": (4, "I"),
    "float": (4, "f"),
    "int64": (8, "q"),
    "uint64": (8, "Q"),
    "double": (8, "d"),
}
#: Basic types whose arrays and sequences rclpy holds as bytes-like objects.
BYTE_TYPES = frozenset({"octet", "uint8"})
#: rosidl type classes (by name) of strings and of sequences.
STRING_TYPES = frozenset({"UnboundedString", "BoundedString"})
SEQUENCE_TYPES = frozenset({"UnboundedSequence", "BoundedSequence"})


def fields_of(msg_class: type[Any]) -> list[tuple[str, Any]]:
    """(name, rosidl type) of each field of ``msg_class``, in wire order."""
    names = msg_class.get_fields_and_field_types()
    return list(zip(names, msg_class.SLOT_TYPES, strict=True))


def basic_of(slot: Any) -> str | None:
    """The rosidl name of a basic type (``double``, ``uint8``, ...); None for any other type."""
    typename = getattr(slot, "typename", None)
    return typename if type(slot).__name__ == "BasicType" else None


def basic_size(slot: Any) -> int | None:
    """The wire size of a basic type we read and write; None for any other type."""
    basic = basic_of(slot)
    return BASIC[basic][0] if basic in BASIC else None


def nested_class(slot: Any) -> type[Any]:
    """The rclpy class of a nested message type."""
    module = importlib.import_module(".".join(slot.namespaces))
    cls: type[Any] = getattr(module, slot.name)
    return cls
