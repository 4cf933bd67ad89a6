"""Types of the compiled extension (_native.c and the files of _native.h). The records (struct
sequences) are read by name only; their fields are read-only."""

from collections.abc import Sequence
from typing import final

Buffer = bytes | bytearray | memoryview

#: The events of a member's turn in ``Loop.run``'s report.
EVENT_HANDED: int
EVENT_MONITOR: int
EVENT_BROKEN: int
#: The foreign functions a Pump and a RosPump call, by name: what their ``functions`` map to
#: addresses (``abi.py`` finds them in the loaded libraries).
PUMP_FUNCTIONS: tuple[str, ...]
ROS_PUMP_FUNCTIONS: tuple[str, ...]

@final
class Program:
    """One pair's Gazebo -> ROS transcoder (docs/native.md §3)."""

    @property
    def steps(self) -> int:
        """The protobuf fields the last ``to_cdr`` read (its work)."""
    @property
    def kept_bytes(self) -> int:
        """The bytes of output buffer and scratch kept for the next ``to_cdr``."""
    def __init__(self, schema: bytes, ops: bytes) -> None: ...
    def to_cdr(self, payload: Buffer, /) -> tuple[int, bytes | tuple[int, int] | None]: ...

@final
class Encoder:
    """One pair's ROS -> Gazebo transcoder (docs/native.md §6)."""

    def __init__(self, words: bytes) -> None: ...
    def to_pb(self, cdr: Buffer, /) -> tuple[int, bytes | None]: ...

@final
class PumpCounts:
    """A Pump's counts so far: payloads taken off its queue (``received``), of them dropped by
    max_rate and published by the pump; dropped oldest first; ``skipped`` (another spelling of
    a type taken from the same publisher); ``lost`` (no memory to copy them for Python); the
    messages read from the socket (``taken``) and their payload bytes."""

    received: int
    rate_limited: int
    published: int
    dropped: int
    skipped: int
    lost: int
    taken: int
    bytes_read: int

@final
class Refused:
    """A payload no program took."""

    sender: bytes
    msg_type: bytes
    payload: bytes
    status: int

@final
class TooLarge:
    """A payload refused as too large: its list's items, the fewest CDR bytes of one, its size."""

    sender: bytes
    msg_type: bytes
    items: int
    least: int
    size: int

@final
class Handover:
    """What a Pump left to Python since the last ``take_handed``."""

    unrouted: list[list[bytes]]
    refused: list[Refused]
    too_large: list[TooLarge]
    grown: int

@final
class Pump:
    """One Gazebo -> ROS channel's per-message work (docs/native.md §5)."""

    @property
    def dropped_sender(self) -> bytes:
        """The sender of the last payload dropped (b"" before any)."""
    @property
    def handing(self) -> bool:
        """Whether ``take_handed`` has something."""
    def __init__(
        self,
        topic: bytes,
        functions: dict[str, int],
        publisher: int,
        programs: dict[bytes, Program],
        capacity: int,
        max_rate: float,
        max_bytes: int,
    ) -> None: ...
    def read_from(self, sock: int, monitor: int, /) -> None: ...
    def share(self, peers: Sequence[Pump], /) -> None: ...
    def learn(self, sender: Buffer, msg_type: Buffer, take: bool, /) -> bool: ...
    def forget(self) -> None: ...
    def take_handed(self) -> Handover: ...
    def watch(self, size: int, /) -> None: ...
    def counts(self) -> PumpCounts: ...
    def begin_publication(self) -> int: ...
    def end_publication(
        self, sequence: int, ok: bool, written: Buffer | None = None, /
    ) -> None: ...
    def is_own(self, sequence: int, stamp: int, received: Buffer | None = None, /) -> bool: ...
    def guard(self) -> None: ...

@final
class RosPumpCounts:
    """A RosPump's counts so far: messages taken (``received``), of them the bridge's own, those
    max_rate dropped and those sent in every spelling subscribers take (``published``); takes
    rcl refused; messages whose send failed; ``lost`` (no memory to copy them for Python); the
    CDR bytes taken."""

    received: int
    own_skipped: int
    rate_limited: int
    published: int
    take_errors: int
    send_failures: int
    lost: int
    bytes_read: int

@final
class RosPump:
    """One ROS -> Gazebo channel's per-message work (docs/native.md §7)."""

    @property
    def failure(self) -> int:
        """The errno that took the channel off its loop (its socket or eventfd failed), or 0."""
    def __init__(
        self,
        functions: dict[str, int],
        subscription: int,
        sock: int,
        spellings: list[tuple[bytes, bytes, bytes, Encoder]],
        max_rate: float,
    ) -> None: ...
    def set_active(self, types: set[bytes] | frozenset[bytes], /) -> None: ...
    def ignore(self, publishers: Sequence[int], /) -> int: ...
    def take_handed(self) -> list[bytes]: ...
    def send(self, type: Buffer, payload: Buffer, /) -> bool: ...
    def counts(self) -> RosPumpCounts: ...

Member = Pump | RosPump

@final
class Loop:
    """The loop of every native channel of one direction (docs/native.md §5)."""

    def __init__(self, messages: int, slice_ns: int) -> None: ...
    def add(self, member: Member, /) -> None: ...
    def remove(self, member: Member, /) -> bool: ...
    def run(
        self, timeout_ms: int, touched: Sequence[Member], /
    ) -> tuple[bool, list[tuple[Member, int]]]: ...
    def moved(self) -> list[Member]: ...
    def wake(self) -> None: ...
    def size(self) -> int: ...
