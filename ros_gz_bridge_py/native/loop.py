"""The one driver of the native loops: a thread per direction that runs its C ``Loop`` (loop.c)
and does Python's share between the runs (docs/native.md §5, docs/threads.md).

The C loop reads, converts and sends the messages of every member (Gazebo -> ROS: each
channel's :class:`~ros_gz_bridge_py.native.pump.ChannelPump`; ROS -> Gazebo: each channel's
:class:`~ros_gz_bridge_py.native.ros_pump.RosChannelPump`) with the GIL released. Between its
runs the thread turns (:meth:`LoopMember.turn`) the members that need it, and no others:

- a member the loop reports (messages handed back, a connection monitor event, a socket or
  eventfd that cannot be used any more);
- a member that asked (:meth:`NativeLoop.ask`, from any thread: a posted connection change,
  an intra-process message, a new Gazebo subscriber's spelling);
- a member whose own deadline has come (a connection to leave, messages queued in Python);
- a member that took messages since the last count (``Loop.moved``), every
  :data:`COUNT_EVERY` seconds, so the status table stays current within a second; an idle
  loop turns that often only, whatever its number of members.

At each count the bytes a moving member took since the last go to its own ``BurstTrimmer``
(``transport/heap.py``), and the trimmers that hold a burst not trimmed yet are told the time:
once a member that took a burst of large messages has been quiet for a second, freed memory goes
back to the system. A trimmer per member, not one per loop: a fleet's many light channels add up
to more than a quiet rate, and would hold one channel's burst for ever.

Members join and leave from any thread (:meth:`NativeLoop.attach`, :meth:`NativeLoop.detach`,
which returns once neither the C loop nor the thread's Python share touches the member). The
thread starts with the first member and ends with the last. Each direction has its loop
(:func:`shared_loop`), made at its first member.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

from ros_gz_bridge_py.libc import name_os_thread
from ros_gz_bridge_py.native import Extension, extension
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES, TURN_SLICE
from ros_gz_bridge_py.transport.heap import BurstTrimmer, trim_heap

if TYPE_CHECKING:
    from ros_gz_bridge_py.native._native import Member, PumpCounts, RosPumpCounts

_LOG = logging.getLogger("ros_gz_bridge_py.native")
#: The thread of each direction's loop (in Python and in the OS, for ``top -H``).
GZ_TO_ROS, ROS_TO_GZ = "native-gz", "native-ros"
#: Seconds between two counts of the members that moved. Changes are pushed
#: (:meth:`NativeLoop.ask`), so an idle loop wakes this often only, whatever its number of
#: members. Once a second, not 4 times: in a fleet of 25 robots the counts' Python share was
#: 0.34% of a core on native-gz and 0.13% on native-ros at 4 a second, 0.12% and 0.03% at 1.
COUNT_EVERY = 1.0
#: Bytes a member takes before a quiet second is worth a trim: fewer than a Python reader's,
#: because the transcoder's index and output for a large message can be many times its size
#: (4 Pose_V of 4 M empty poses, 32 MB, left 72 MB on the loop thread's own heap).
LOOP_TRIM_AFTER = 8 * 1024 * 1024


class LoopMember(Protocol):
    """What a loop runs: a C pump (``Pump`` or ``RosPump``) and its channel's Python share."""

    #: The C pump.
    pump: Member

    @property
    def bytes_read(self) -> int:
        """Payload bytes it took so far (for the trim)."""
        ...

    def turn(self, *, handed: bool, monitor: bool, broken: bool) -> float | None:
        """Python's share, on the loop's thread (``handed``, ``monitor``, ``broken``: what its
        C turns reported; none: a count, a deadline or a request). Returns when the member
        wants its next turn at the latest (``time.monotonic()``), or None."""
        ...


class PumpMember(LoopMember):
    """What both kinds of channel member (``pump.py``, ``ros_pump.py``) do alike: the bytes
    their C pump took, its counts since the last look, and joining their direction's loop
    (releasing what the member holds for the loop if it cannot)."""

    _loop: NativeLoop
    _seen: PumpCounts | RosPumpCounts

    @property
    def bytes_read(self) -> int:
        """Payload bytes the C pump took so far (:class:`NativeLoop` trims after a burst)."""
        return self.pump.counts().bytes_read

    def _deltas(self, *names: str) -> tuple[int, ...]:
        """The counts ``names`` of the C pump since the last call."""
        now, before = self.pump.counts(), self._seen
        self._seen = now
        return tuple(getattr(now, name) - getattr(before, name) for name in names)

    def _join(self) -> None:
        try:
            self._loop.attach(self)
        except Exception:
            self._release()
            raise

    def _release(self) -> None:
        """Lets go of what the member holds while on the loop."""
        raise NotImplementedError


class NativeLoop:
    """One direction's loop thread (see the module docstring)."""

    def __init__(
        self, native: Extension, name: str, *, trim: Callable[[], object] = trim_heap
    ) -> None:
        self.name = name
        self._loop = native.Loop(TURN_MESSAGES, round(TURN_SLICE * 1e9))
        self._bits = int(native.EVENT_HANDED), int(native.EVENT_MONITOR), int(native.EVENT_BROKEN)
        self._trim = trim  # what each member's trimmer calls
        self._lock = threading.Lock()  # the thread and the requests
        #: Held while the thread does members' Python share; membership changes wait for it.
        self._turning = threading.RLock()
        self._thread: threading.Thread | None = None
        self._asked: set[LoopMember] = set()
        self._members: dict[Member, LoopMember] = {}  # by pump
        self._deadlines: dict[LoopMember, float] = {}
        self._trimmers: dict[LoopMember, BurstTrimmer] = {}
        self._bytes_read: dict[LoopMember, int] = {}  # at the last count
        self._pending: set[LoopMember] = set()  # whose trimmer holds a burst
        self._touched: list[Member] = []

    # --- from any thread ----------------------------------------------------------------------

    def attach(self, member: LoopMember) -> None:
        """Run ``member`` from now on; the thread starts with the first member."""
        with self._turning:
            self._members[member.pump] = member
            self._trimmers[member] = BurstTrimmer(self._trim, trim_after=LOOP_TRIM_AFTER)
            self._bytes_read[member] = member.bytes_read
            try:
                self._loop.add(member.pump)
            except Exception:
                self._forget(member)
                raise
        with self._lock:
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
                self._thread.start()

    def detach(self, member: LoopMember) -> None:
        """Stop running ``member`` (idempotent); once this returns, neither the C loop nor the
        thread's Python share touches it."""
        self._loop.remove(member.pump)
        with self._turning:  # after a turn of the thread that may be working for it
            self._forget(member)
        self._loop.wake()  # the thread ends with the last member

    def exclusive(self) -> threading.RLock:
        """Held, no member's Python share runs but the holder's (re-entrant: a member's turn
        may take it, and attach and detach within it)."""
        return self._turning

    def ask(self, member: LoopMember) -> None:
        """Turn ``member`` soon (quick)."""
        with self._lock:
            self._asked.add(member)
        self._loop.wake()

    @property
    def thread(self) -> threading.Thread | None:
        """The loop's thread while it has members."""
        return self._thread

    def size(self) -> int:
        """How many members the loop runs."""
        return self._loop.size()

    def _forget(self, member: LoopMember) -> None:
        if self._members.get(member.pump) is member:
            del self._members[member.pump]
        self._deadlines.pop(member, None)
        self._trimmers.pop(member, None)
        self._bytes_read.pop(member, None)
        self._pending.discard(member)

    # --- the loop's thread --------------------------------------------------------------------

    def _run(self) -> None:
        name_os_thread(self.name)
        next_count = time.monotonic() + COUNT_EVERY
        while True:
            with self._lock:
                asked, self._asked = self._asked, set()
                if not self._members:
                    self._thread = None
                    return
            try:
                next_count = self._iterate(asked, next_count)
            except Exception:  # the loop must survive anything: every native channel is on it
                _LOG.exception("the native loop %s failed a turn", self.name)
                time.sleep(0.01)

    def _iterate(self, asked: set[LoopMember], next_count: float) -> float:
        """One round: the members due, one C run, what it reported; returns when the moving
        members are counted next."""
        with self._turning:
            now = time.monotonic()
            due = asked | {member for member, at in self._deadlines.items() if at <= now}
            for member in due:
                self._turn(member, 0)
            wait = min([next_count, *self._deadlines.values()]) - now
        _woken, reported = self._loop.run(max(0, int(wait * 1000) + 1), self._touched)
        self._touched = []
        with self._turning:
            for pump, events in reported:
                self._turn(self._members.get(pump), events)
            now = time.monotonic()
            if now < next_count:
                return next_count
            moved = [self._members[pump] for pump in self._loop.moved() if pump in self._members]
            for mover in moved:
                self._turn(mover, 0)
            self._count_bytes(moved, now)
            return now + COUNT_EVERY

    def _count_bytes(self, moved: list[LoopMember], now: float) -> None:
        """The bytes each of the ``moved`` members took since the last count to its trimmer;
        then the trimmers holding a burst trim if it is over."""
        for member in moved:
            trimmer = self._trimmers.get(member)
            if trimmer is None:
                continue  # detached since
            total = member.bytes_read
            trimmer.received(total - self._bytes_read[member], now)
            self._bytes_read[member] = total
            if trimmer.pending:
                self._pending.add(member)
        for member in list(self._pending):
            trimmer = self._trimmers[member]
            trimmer.idle(now)
            if not trimmer.pending:
                self._pending.discard(member)

    def _turn(self, member: LoopMember | None, events: int) -> None:
        if member is None or self._members.get(member.pump) is not member:
            return  # detached since
        self._touched.append(member.pump)
        handed, monitor, broken = (bool(events & bit) for bit in self._bits)
        deadline: float | None = None
        try:
            deadline = member.turn(handed=handed, monitor=monitor, broken=broken)
        except Exception:
            _LOG.exception("a native channel's turn failed")
        if self._members.get(member.pump) is not member:
            return  # it left in its turn
        if deadline is None:
            self._deadlines.pop(member, None)
        else:
            self._deadlines[member] = deadline


_LOOPS: dict[str, NativeLoop] = {}
_LOOPS_LOCK = threading.Lock()


def shared_loop(name: str) -> NativeLoop:
    """The process's loop of one direction (:data:`GZ_TO_ROS` or :data:`ROS_TO_GZ`), made on
    first use.

    Raises:
        RuntimeError: the native extension is not built.
    """
    with _LOOPS_LOCK:
        loop = _LOOPS.get(name)
        if loop is None:
            native = extension()
            if native is None:
                msg = "no native extension"
                raise RuntimeError(msg)
            loop = _LOOPS[name] = NativeLoop(native, name)
        return loop
