"""One SUB socket read for several native Gazebo -> ROS channels (docs/native.md §5).

A socket per topic gives each topic TCP connections of its own, so each message wakes libzmq's
I/O thread and the loop alone. Small messages are cheaper read as Gazebo's own subscribers read
them: every topic of a publishing process through one socket and one connection, a TCP read
bringing several messages (benchmarks/reports/socket_sharing.md). A :class:`SocketReader` is the
member of the Gazebo -> ROS loop that reads such a socket: a C ``Pump`` with no publisher of its
own whose peers (``Pump.share``) are the channels' pumps. The loop puts each message in its
topic's queue and delivers every queue in the reader's turns; the reader's Python share is its
socket's host's (connections, posted commands) and then each channel's (what its pump handed
back, its counts).

The peers change only while the reader is off the loop: adding or removing a channel takes the
reader off and puts it back (from any thread, or in a turn on the loop's own), so once
:meth:`SocketReader.remove` returns nothing touches the channel's pump.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.abi import zmq_functions
from ros_gz_bridge_py.native.loop import GZ_TO_ROS, PumpMember, shared_loop
from ros_gz_bridge_py.transport.api import NativeHost

if TYPE_CHECKING:
    from ros_gz_bridge_py.native._native import Pump
    from ros_gz_bridge_py.native.pump import ChannelPump


class SocketReader(PumpMember):
    """The loop member that reads ``sock`` (with its connection ``monitor``) for the channels
    added to it; ``host`` is the socket's owner (see the module docstring)."""

    def __init__(self, sock: int, monitor: int, host: NativeHost) -> None:
        native, functions = extension(), zmq_functions()
        if native is None or functions is None:
            msg = "no native extension or foreign functions"
            raise RuntimeError(msg)
        # No publisher and no program: only its peers' messages are delivered.
        self.pump: Pump = native.Pump(b"", functions, 0, {}, 1, 0.0, 1)
        self.pump.read_from(sock, monitor)
        self._host = host
        self._loop = shared_loop(GZ_TO_ROS)
        self._peers: list[ChannelPump] = []
        #: When each channel wants its next turn at the latest (its last turn said).
        self._deadlines: dict[ChannelPump, float | None] = {}
        self._closed = False
        self._join()

    def add(self, channel: ChannelPump) -> None:
        """Read the channel's topic for it from now on."""
        with self._loop.exclusive():
            self._reshare([*self._peers, channel])

    def remove(self, channel: ChannelPump) -> None:
        """Returns once nothing reads for the channel (idempotent)."""
        with self._loop.exclusive():
            if channel in self._peers:
                self._reshare([peer for peer in self._peers if peer is not channel])

    def wake(self) -> None:
        """The host wants a turn soon (any thread)."""
        self._loop.ask(self)

    def close(self) -> None:
        """Off the loop, every channel let go. Idempotent."""
        with self._loop.exclusive():
            self._closed = True
            self._loop.detach(self)
            self._peers = []
            self.pump.share([])

    def _reshare(self, peers: list[ChannelPump]) -> None:
        """Off the loop, the peers changed, back on it; peers refused leave it as it was."""
        self._loop.detach(self)
        try:
            self.pump.share([peer.pump for peer in peers])
        except BaseException:
            if not self._closed:
                self._join()
            raise
        self._peers = peers
        self._deadlines = {peer: self._deadlines.get(peer) for peer in peers}
        if not self._closed:
            self._join()

    def _release(self) -> None:
        """Nothing is held for the loop besides the peers' publishers (held by each)."""

    # --- the loop's thread (loop.py LoopMember) --------------------------------------------

    def turn(self, *, handed: bool, monitor: bool, broken: bool) -> float | None:
        """The host's share (connections, posted commands), then the channels': what their
        pumps handed back where the turn is for that (a fleet's channel learning its routes
        turns no other), every channel's counts and queue otherwise. A message of a topic no
        channel reads any more (before its socket's subscription went) is nobody's."""
        if handed:
            self.pump.take_handed()
        own = self._host.native_turn([], monitor=monitor, broken=broken)
        only_handing = handed and not monitor and not broken
        for peer in list(self._peers):
            if not only_handing or peer.pump.handing:
                wants = peer.turn(handed=peer.pump.handing, monitor=False, broken=False)
                if peer in self._peers:  # else it left in its turn (a socket of its own)
                    self._deadlines[peer] = wants
        due = [wants for wants in self._deadlines.values() if wants is not None]
        if own is not None:
            due.append(own)
        return min(due) if due else None
