"""Which spelling of a message type a publisher puts on the wire (docs/protocol-lines.md §9).

A publisher of ``gz.msgs.Twist`` is announced under both spellings, so a typed Fortress
subscriber (``ignition.msgs.Twist``) and a typed Harmonic one (``gz.msgs.Twist``) both take it.
Each message must then reach every remote subscriber exactly once, in a spelling it accepts:

* a typed subscriber registers for one spelling: send that one;
* a generic subscriber (``gz topic -e``, a log recorder) takes every spelling, and registers
  for both announcements on ZeroMQ (or says ``google.protobuf.Message`` on Zenoh): send it
  once, in the spelling its Gazebo line decodes.

Both backends feed this with what their discovery learned; nothing here does I/O.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling, respell, spelling_of
from ros_gz_bridge_py.watchers import Watchers


@dataclass(frozen=True, slots=True)
class RemoteSubscriber:
    """One remote node subscribed to a topic, with every type name it registered for."""

    process_uuid: str
    node_uuid: str
    types: frozenset[str]


def wire_types(
    names: tuple[str, ...],
    subscribers: Iterable[RemoteSubscriber],
    peer_spelling: Callable[[str], Spelling | None],
) -> frozenset[str]:
    """The spellings among ``names`` (ours, preferred first) to send for ``subscribers``.

    ``peer_spelling`` tells the spelling of a peer process when its line is known.
    """
    wanted: set[str] = set()
    for sub in subscribers:
        matching = sub.types.intersection(names)
        if GENERIC_TYPE in sub.types or len(matching) > 1:
            spelling = peer_spelling(sub.process_uuid)
            wanted.add(names[0] if spelling is None else respell(names[0], spelling))
        else:
            wanted.update(matching)
    return frozenset(wanted)


class PeerSpellings:
    """What each peer process calls its messages, from what it was seen to send.

    A process that advertises or subscribes types of one spelling uses that spelling. Failing
    that, on ZeroMQ, gz-transport 13 and later fill a publisher record in every heartbeat and
    11 (Fortress) and 12 (Garden) do not: those are ``legacy`` (``ignition.msgs``, unless the
    user says the simulator is Garden).
    """

    def __init__(self, legacy: Spelling = Spelling.IGNITION) -> None:
        self.legacy = legacy
        #: Bumped whenever the spelling of some process changes.
        self.version = 0
        self._typed: dict[str, set[Spelling]] = {}
        self._by_heartbeat: dict[str, Spelling] = {}
        #: Processes whose heartbeats carry a record (gz-transport 13+), and those without.
        self.modern: set[str] = set()
        self.legacy_processes: set[str] = set()

    def saw_type(self, process_uuid: str, type_name: str) -> None:
        """Note a type name ``process_uuid`` advertised or subscribed."""
        spelling = spelling_of(type_name)
        if spelling is not None:
            before = self.of(process_uuid)
            self._typed.setdefault(process_uuid, set()).add(spelling)
            self._changed(before, process_uuid)

    def saw_heartbeat(self, process_uuid: str, with_record: bool) -> None:
        """Note a ZeroMQ heartbeat, with or without a publisher record in it."""
        before = self.of(process_uuid)
        self._by_heartbeat[process_uuid] = Spelling.GZ if with_record else self.legacy
        (self.modern if with_record else self.legacy_processes).add(process_uuid)
        self._changed(before, process_uuid)

    def forget(self, process_uuid: str) -> None:
        before = self.of(process_uuid)
        self._typed.pop(process_uuid, None)
        self._by_heartbeat.pop(process_uuid, None)
        self.modern.discard(process_uuid)
        self.legacy_processes.discard(process_uuid)
        self._changed(before, process_uuid)

    def _changed(self, before: Spelling | None, process_uuid: str) -> None:
        if self.of(process_uuid) is not before:
            self.version += 1

    def of(self, process_uuid: str) -> Spelling | None:
        """The spelling ``process_uuid`` uses, or None when nothing tells it yet."""
        typed = self._typed.get(process_uuid, set())
        if len(typed) == 1:
            return next(iter(typed))
        return self._by_heartbeat.get(process_uuid)

    def snapshot(self) -> dict[str, Spelling]:
        """Every known process spelling (a new dict, safe to read from other threads)."""
        known = {p: s for p in self._by_heartbeat if (s := self.of(p)) is not None}
        known.update({p: s for p in self._typed if (s := self.of(p)) is not None})
        return known


class SubscriberBook:
    """The remote subscribers of each topic and the spellings of their processes.

    The node's discovery thread replaces whole entries (never mutates them) and bumps
    ``version``; publishing threads read without a lock and cache what they computed per
    version (:class:`WireTypeCache`). ``default_spelling`` is assumed for processes whose
    spelling is unknown (None: the publisher's own spelling). Those that cannot ask at every
    message are called after each change (:meth:`watch`).
    """

    def __init__(self, default_spelling: Spelling | None = None) -> None:
        self.version = 0
        self._default = default_spelling
        self._subscribers: dict[str, tuple[RemoteSubscriber, ...]] = {}
        self._spellings: dict[str, Spelling] = {}
        #: fqn -> what to call when its subscribers or the spellings change.
        self._watchers: dict[str, Watchers] = {}

    def watch(self, fqn: str, changed: Callable[[], None]) -> Callable[[], None]:
        """Call ``changed()`` after each change of ``fqn``'s subscribers or of the spellings,
        on the thread that made it (it must be quick and must not raise); returns the function
        that stops it."""
        return self._watchers.setdefault(fqn, Watchers()).add(changed)

    def _changed(self, fqn: str | None) -> None:
        """Bump the version and tell the watchers of ``fqn`` (None: of every topic)."""
        self.version += 1
        if fqn is None:
            for watchers in list(self._watchers.values()):
                watchers.notify()
        elif (topic_watchers := self._watchers.get(fqn)) is not None:
            topic_watchers.notify()

    def set_subscribers(self, fqn: str, subscribers: tuple[RemoteSubscriber, ...]) -> None:
        """Replace the remote subscribers of ``fqn``."""
        entries = dict(self._subscribers)
        if subscribers:
            entries[fqn] = subscribers
        else:
            entries.pop(fqn, None)
        self._subscribers = entries
        self._changed(fqn)

    def set_spellings(self, spellings: dict[str, Spelling]) -> None:
        """Replace the known spellings of peer processes."""
        self._spellings = spellings
        self._changed(None)

    def subscribers(self, fqn: str) -> tuple[RemoteSubscriber, ...]:
        return self._subscribers.get(fqn, ())

    def spelling(self, process_uuid: str) -> Spelling | None:
        """The spelling of peer ``process_uuid``: known, else the default (may be None)."""
        return self._spellings.get(process_uuid, self._default)

    def wire_types(self, fqn: str, names: tuple[str, ...]) -> frozenset[str]:
        """What a publisher of ``names`` on ``fqn`` sends now (see :func:`wire_types`)."""
        spellings = self._spellings
        default = self._default
        return wire_types(
            names, self._subscribers.get(fqn, ()), lambda process: spellings.get(process, default)
        )


class WireTypeCache:
    """One publisher's current wire types, recomputed only when the book changed."""

    def __init__(self, book: SubscriberBook, fqn: str, names: tuple[str, ...]) -> None:
        self._book = book
        self._fqn = fqn
        self._names = names
        self._version = -1
        self._types: frozenset[str] = frozenset()

    def get(self) -> frozenset[str]:
        version = self._book.version
        if version != self._version:
            self._types = self._book.wire_types(self._fqn, self._names)
            self._version = version
        return self._types
