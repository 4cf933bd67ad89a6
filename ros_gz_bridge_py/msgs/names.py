"""Gazebo message type names and the two spellings of every message (docs/protocol-lines.md §9).

Fortress (and Citadel) name their messages ``ignition.msgs.X``; Garden and later ``gz.msgs.X``.
The bytes of a message are the same under both names (except the IMU layout, which the
converters handle), but Gazebo Transport matches type names as exact strings. The bridge
serves every line, so it treats the two spellings as one message and puts on the wire the
spelling each peer understands.
"""

from __future__ import annotations

import enum

GZ_PREFIX = "gz.msgs."
IGNITION_PREFIX = "ignition.msgs."
#: The type name Gazebo Transport uses for "any message type" (generic subscribers).
GENERIC_TYPE = "google.protobuf.Message"


class Spelling(enum.Enum):
    """Which prefix a Gazebo line writes its message types with."""

    #: Citadel and Fortress (ign-msgs 5-8).
    IGNITION = IGNITION_PREFIX
    #: Garden and every later line (gz-msgs 9+).
    GZ = GZ_PREFIX


def spelling_of(type_name: str) -> Spelling | None:
    """The prefix family of ``type_name``; None for a name with neither prefix."""
    if type_name.startswith(GZ_PREFIX):
        return Spelling.GZ
    if type_name.startswith(IGNITION_PREFIX):
        return Spelling.IGNITION
    return None


def respell(type_name: str, spelling: Spelling) -> str:
    """``type_name`` written with ``spelling``'s prefix; a name with neither prefix unchanged."""
    current = spelling_of(type_name)
    if current is None or current is spelling:
        return type_name
    return spelling.value + type_name.removeprefix(current.value)


def canonical_type(type_name: str) -> str:
    """``gz.msgs.X`` for either spelling of X; any other name unchanged."""
    return respell(type_name, Spelling.GZ)


def spellings(type_name: str) -> tuple[str, ...]:
    """``type_name`` first, then its other spelling if it has one."""
    if spelling_of(type_name) is None:
        return (type_name,)
    other = respell(
        type_name, Spelling.IGNITION if type_name.startswith(GZ_PREFIX) else Spelling.GZ
    )
    return (type_name, other)


def same_message(a: str, b: str) -> bool:
    """True if ``a`` and ``b`` name the same message (equal, or the two spellings of one)."""
    return canonical_type(a) == canonical_type(b)
