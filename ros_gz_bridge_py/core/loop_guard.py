"""Recognise, on a ROS subscription, the messages the bridge itself published.

A bidirectional bridge publishes Gazebo messages on a ROS topic it also subscribes to; without a
filter every message would go back to Gazebo. The C++ bridge (Jazzy 1.0.21+) skips samples whose
publisher GID is one of its own. rclpy does not expose the publisher GID of a received sample,
but it does expose the writer's ``publication_sequence_number`` and the ``source_timestamp``
(the wall clock when the writer wrote it). A sample is ours when its sequence number is one our
publisher used, its source timestamp falls inside the wall-clock window of that publish call,
and, where the subscription hands over the sample, its content is what we published.

The content check is not a formality: another node publishing in step with Gazebo (each of its
messages right after one of Gazebo's, both counted from 1) meets our publisher's numbers one for
one, and on a loaded machine a publish call lasts long enough for the other write to fall inside
it; without the content its messages were skipped as ours (one in ten of such a lockstep batch on
2 busy cores). On a guarded topic, what each remembered publication was is kept as its CDR
length and ends, and compared as CDR. Unlike
``ignore_local_publications``, none of this drops messages from other nodes in the same
process (ros_gz issue #788).
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Mapping
from typing import Any, Protocol

from rclpy.serialization import serialize_message

from ros_gz_bridge_py.watchers import Watchers

#: How many recent publications per ROS topic are remembered (covers bursts and slow executors).
HISTORY = 1024
#: The end of the window of a publish call that has not returned yet.
_STILL_PUBLISHING = 2**63
#: How many bytes of each end of a CDR message are kept to know it again.
_ENDS = 256


def _ends(cdr: bytes | bytearray | memoryview) -> tuple[int, bytes, bytes]:
    """A CDR message's body length and ends: the whole of a small message; of a large one the
    header (stamp, frame) and the last bytes, which a different message practically never
    shares with ours at the same sequence number and time.

    The body is what follows the 4-byte encapsulation header, less the padding a middleware
    may add on the way to a multiple of 4 bytes: the count XTypes puts in the options' last
    two bits (CycloneDDS), then trailing zero bytes (Fast DDS before 2.1 padded with zeros
    and said nothing). Our own sample must compare equal whatever the middleware did to it.
    """
    body = bytes(cdr[4 : max(4, len(cdr) - (cdr[3] & 3))]) if len(cdr) >= 4 else bytes(cdr)
    body = body.rstrip(b"\0")
    return len(body), body[:_ENDS], body[-_ENDS:]


def _as_cdr(message: Any) -> Any:
    """``message`` as CDR bytes: as it is if it is, else serialized."""
    if isinstance(message, (bytes, bytearray, memoryview)):
        return message
    return serialize_message(message)


def _as_ends(content: Any) -> tuple[int, bytes, bytes]:
    """``content`` (kept or received: an object, CDR bytes or their ends) as CDR ends.
    Compared as CDR, not as objects: a NaN field makes a message unequal to itself."""
    if isinstance(content, tuple):
        return content
    return _ends(_as_cdr(content))


class NumberedPublisher(Protocol):
    """A publisher that numbers and times its publications itself (a native channel's pump,
    ``native/pump.py``, whose C loop publishes without Python)."""

    def is_own(self, sequence: int, stamp: int, received: bytes | None, /) -> bool:
        """Whether we wrote sample ``sequence`` stamped ``stamp``; ``received``, its CDR
        where known, must then be what we published."""
        ...

    def guard(self) -> None:
        """Keep what each publication was from now on."""
        ...


class OwnPublications:
    """Windows of our own recent publications on one ROS topic, from one or more publishers."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        # (publisher id, sequence number) -> (start ns, end ns) of the publish call, and what
        # was published once it returned (_ends; None before the topic was guarded).
        self._windows: OrderedDict[tuple[int, int], tuple[int, int, Any]] = OrderedDict()
        self._sequences: dict[int, int] = {}
        self._guarded = False
        self._numbered: list[NumberedPublisher] = []
        #: The rcl publishers (addresses) the bridge has on the topic: a native ROS -> Gazebo
        #: loop skips their samples by publisher GID (``native/ros_pump.py``).
        self._rcl_publishers: frozenset[int] = frozenset()
        self._rcl_watchers = Watchers()

    def add_rcl_publisher(self, pointer: int) -> None:
        with self._lock:
            self._rcl_publishers = self._rcl_publishers | {pointer}
        self._rcl_watchers.notify()

    def remove_rcl_publisher(self, pointer: int) -> None:
        with self._lock:
            self._rcl_publishers = self._rcl_publishers - {pointer}
        self._rcl_watchers.notify()

    def rcl_publishers(self) -> frozenset[int]:
        """The rcl publishers of the bridge on this topic now."""
        return self._rcl_publishers

    def watch_rcl_publishers(self, changed: Callable[[], None]) -> Callable[[], None]:
        """Call ``changed()`` (quick, on the caller's thread) after each change of
        :meth:`rcl_publishers`; returns the function that stops it."""
        return self._rcl_watchers.add(changed)

    def guard(self) -> None:
        """A subscription of the bridge judges samples of this topic from now on: keep what
        each publication was (only then: it costs a little on every publish)."""
        with self._lock:
            self._guarded = True
            numbered = list(self._numbered)
        for publisher in numbered:
            publisher.guard()

    def add_numbered(self, publisher: NumberedPublisher) -> None:
        """Also ask ``publisher`` whether a sample is ours (until :meth:`remove_numbered`)."""
        with self._lock:
            self._numbered.append(publisher)
            guarded = self._guarded
        if guarded:
            publisher.guard()

    def remove_numbered(self, publisher: NumberedPublisher) -> None:
        with self._lock:
            if publisher in self._numbered:
                self._numbered.remove(publisher)

    def wrap(self, publisher: Any) -> Callable[[Any], None]:
        """A publish function for ``publisher`` that records each publication's window.

        Must be the only way ``publisher`` publishes, from one thread at a time, so the
        sequence numbers stay in step. The window opens before the call: the sample can reach
        our own subscription (on another thread) before ``publish`` returns, all the more
        when the write is made with the GIL released. Once the topic is guarded, what was
        published is kept as CDR ends: the bytes ``publish`` says it wrote, if any
        (``ros/serialized_publisher.py``), else the message (serialized if an object).
        """
        key = id(publisher)
        publish = publisher.publish

        def publish_and_record(msg: Any) -> None:
            start = time.time_ns()
            # During the call the message itself: its sample may come back before it returns.
            kept = msg if self._guarded else None
            with self._lock:
                sequence = self._sequences.get(key, 0) + 1
                self._sequences[key] = sequence
                self._windows[(key, sequence)] = (start, _STILL_PUBLISHING, kept)
                if len(self._windows) > HISTORY:
                    self._windows.popitem(last=False)
            try:
                written = publish(msg)
            except BaseException:
                with self._lock:  # nothing was written: the number was not used
                    self._sequences[key] = sequence - 1
                    self._windows.pop((key, sequence), None)
                raise
            end = time.time_ns()
            if kept is not None:
                kept = _as_ends(msg if written is None else written)
            with self._lock:
                if (key, sequence) in self._windows:
                    self._windows[(key, sequence)] = (start, end, kept)

        return publish_and_record

    def is_own(self, info: Mapping[str, Any], received: Any = None) -> bool:
        """True when the sample described by rclpy's message info, and ``received`` (the
        sample itself, where the caller has it), is one we published."""
        sequence = info.get("publication_sequence_number")
        stamp = info.get("source_timestamp")
        if not sequence or not stamp:
            return False
        matched = []
        with self._lock:
            for key in self._sequences:
                window = self._windows.get((key, sequence))
                if window is not None and window[0] <= stamp <= window[1]:
                    matched.append(window[2])
            numbered = list(self._numbered)
        if matched and (received is None or any(kept is None for kept in matched)):
            return True
        if not matched and not numbered:
            return False
        # The sample serialized once, for our windows and the numbered publishers alike.
        cdr = None if received is None else _as_cdr(received)
        if matched and cdr is not None:
            ends = _ends(cdr)
            if any(_as_ends(kept) == ends for kept in matched):
                return True
        return any(publisher.is_own(sequence, stamp, cdr) for publisher in numbered)
