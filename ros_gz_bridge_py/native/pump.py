"""A native Gazebo -> ROS channel's pump, as its socket's owner and its channel use it
(docs/native.md §5).

:class:`ChannelPump` holds the C ``Pump`` (pump.c) of one channel: made when the channel's ROS
publisher exists, with one program per spelling of the channel's Gazebo type, and kept for the
publisher's life (its publication sequence numbers are the loop guard's, whichever path
published). The topic's native reader (``transport/zmq/reader.py``) attaches it, with its
socket owner's socket, to the Gazebo -> ROS loop (``loop.py``) instead of reading the socket on
a thread of its own. Its turns, on the loop's thread, do what the C pump left to Python: the
frames of a sender not yet known go to the reader (whose socket owner judges them, as on the
Python path); the payloads no program took go to the channel's Python path on the process's one
fallback thread (``fallback.py``), behind a drop-oldest queue of the channel's own, so that a
payload slow to refuse (a Pose_V of 4 M empty poses: a second of parsing) holds up no channel's
loop; and the counts go to the channel.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from ros_gz_bridge_py.converters._limits import amplification_error
from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.abi import zmq_functions
from ros_gz_bridge_py.native.fallback import fallback_worker
from ros_gz_bridge_py.native.loop import GZ_TO_ROS, PumpMember, shared_loop
from ros_gz_bridge_py.native.socket_reader import SocketReader
from ros_gz_bridge_py.transport import MessageInfo
from ros_gz_bridge_py.transport.api import NativeHost, NativeSocketReader

if TYPE_CHECKING:
    from ros_gz_bridge_py.native._native import Program, Pump


class ChannelPump(PumpMember):
    """One channel's C pump (see the module docstring).

    ``programs``: the compiled program of each wire spelling the channel takes.
    ``refused(payload, info)``: the channel's Python path for one admitted payload.
    ``failed(error)``: counts a payload the C pump refused itself (on the loop's thread).
    ``counted(received, rate_limited, published)``: what the loop did since it last said.
    """

    def __init__(
        self,
        *,
        topic: str,
        publisher: Any,
        programs: Mapping[str, Program],
        capacity: int,
        max_bytes: int,
        max_rate: float,
        refused: Callable[[bytes, MessageInfo], None],
        failed: Callable[[Exception], None],
        counted: Callable[[int, int, int], None],
        partition: str,
        name: str,
    ) -> None:
        native, functions = extension(), zmq_functions()
        if native is None or functions is None:
            msg = "no native extension or foreign functions"
            raise RuntimeError(msg)
        self._handle = publisher.handle
        self.pump: Pump = native.Pump(
            topic.encode(),
            functions,
            publisher.handle.pointer,
            {name.encode(): program for name, program in programs.items()},
            capacity,
            max_rate,
            max_bytes,
        )
        self._loop = shared_loop(GZ_TO_ROS)
        self._host: NativeHost | None = None
        self._reader: SocketReader | None = None  # while another reads the channel's topic
        self._holding = False  # the publisher's handle, while the loop publishes on it
        self._failed = failed
        self._counted = counted
        #: The refused payloads on their way to ``refused``.
        self._fallback = fallback_worker().lane(refused, capacity, max_bytes, name)
        self._partition = partition
        self._name = name
        self._infos: dict[tuple[bytes, bytes], MessageInfo] = {}
        self._seen = self.pump.counts()

    # --- the socket owner (transport/api.py NativeLoop) -----------------------------------

    def learn(self, sender: bytes, msg_type: bytes, *, take: bool) -> None:
        """Messages of (``sender``, ``msg_type``) go natively from now on (``take``; where a
        program takes the type), or are skipped (another spelling of a type taken)."""
        self.pump.learn(sender, msg_type, take)

    def attach(self, sock: int, monitor: int, host: NativeHost) -> None:
        """Read ``sock`` (with its connection ``monitor``) on the process's loop, with the
        routes learned so far; ``host`` does the socket owner's share on the loop's thread."""
        self._host = host
        self.pump.read_from(sock, monitor)
        self.pump.forget()
        if not self._holding:
            self._handle.__enter__()  # the publisher stays while the loop publishes on it
            self._holding = True
        self._join()

    def socket_reader(self, sock: int, monitor: int, host: NativeHost) -> SocketReader:
        """A reader of ``sock`` (with its connection ``monitor``) on this channel's loop, for
        the channels :meth:`attach_shared` gives it; ``host`` is the socket's owner."""
        return SocketReader(sock, monitor, host)

    def attach_shared(self, reader: NativeSocketReader, host: NativeHost) -> None:
        """Take the topic's messages from ``reader``'s socket (made by :meth:`socket_reader`),
        with the routes learned so far; ``host`` does the topic's share on the loop's thread."""
        if not isinstance(reader, SocketReader):
            msg = f"not a native socket reader: {reader!r}"
            raise TypeError(msg)
        self._host = host
        self.pump.forget()
        if not self._holding:
            self._handle.__enter__()  # the publisher stays while the loop publishes on it
            self._holding = True
        self._reader = reader
        reader.add(self)

    def detach(self) -> None:
        """Returns once the loop no longer reads the socket, nor a reader for the channel."""
        if self._reader is not None:
            self._reader.remove(self)
            self._reader = None
        self._loop.detach(self)
        self._count()  # what the loop did after its last turn of the channel (a lazy close)
        self._release()

    def wake(self) -> None:
        """The host wants a turn soon (any thread): the loop turns the channel, or the
        reader that reads for it."""
        reader = self._reader
        if reader is not None:
            reader.wake()
        else:
            self._loop.ask(self)

    def watch(self, size: int | None) -> None:
        """Payloads larger than ``size`` are told to the host (None: none); on the loop's
        thread, or before the pump is attached."""
        self.pump.watch(-1 if size is None else size)

    def _release(self) -> None:
        if self._holding:
            self._holding = False
            self._handle.__exit__(None, None, None)

    # --- the loop's thread (loop.py LoopMember) --------------------------------------------

    def turn(self, *, handed: bool, monitor: bool, broken: bool) -> float | None:
        """What the C loop left to Python: refused payloads to the fallback thread, payloads
        refused as too large counted, the counts; then the host's own turn with the frames of
        senders not known yet."""
        handover = self.pump.take_handed() if handed else None
        self._count()
        for large in handover.too_large if handover else ():
            self._failed(
                amplification_error(large.items, "items", large.size, large.items * large.least)
            )
        for refused in handover.refused if handover else ():
            self._fallback.put(refused.payload, self._info(refused.sender, refused.msg_type))
        if self._host is None:
            return None
        return self._host.native_turn(
            handover.unrouted if handover else [],
            monitor=monitor,
            broken=broken,
            grown=handover.grown if handover else 0,
        )

    def _count(self) -> None:
        """What the loop did since it last said, to the channel."""
        deltas = self._deltas("received", "rate_limited", "published")
        if any(deltas):
            self._counted(*deltas)

    def _info(self, sender: bytes, msg_type: bytes) -> MessageInfo:
        info = self._infos.get((sender, msg_type))
        if info is None:
            info = MessageInfo(
                self._name, msg_type.decode(), self._partition, sender.decode(),
                intra_process=False,
            )  # fmt: skip
            self._infos[(sender, msg_type)] = info
        return info

    def close(self) -> None:
        """No more payloads to the Python path (after the one being converted, if it is this
        channel's). Idempotent."""
        self._fallback.close()

    # --- the counts --------------------------------------------------------------------------

    @property
    def received(self) -> int:
        """Payloads taken from the socket so far."""
        return self.pump.counts().received

    @property
    def dropped_sender(self) -> str:
        """The sender of the last payload dropped ("" before any)."""
        return self.pump.dropped_sender.decode(errors="replace")

    @property
    def dropped(self) -> int:
        """Payloads dropped so far: the oldest, before any work on them (over the queue's count
        or bytes, natively or on the way to the Python path), and those that could not be
        handed to Python (no memory for a copy)."""
        counts = self.pump.counts()
        return counts.dropped + counts.lost + self._fallback.dropped

    # --- the loop guard -----------------------------------------------------------------------

    def wrap(self, publish: Callable[[Any], Any]) -> Callable[[Any], None]:
        """``publish`` (the channel's Python path on the same publisher) numbered in the same
        sequence as the pump's own publications; the CDR it wrote (what it returns, or the
        message if it is CDR) is the publication's digest."""
        pump = self.pump

        def publish_and_record(msg: Any) -> None:
            sequence = pump.begin_publication()
            try:
                written = publish(msg)
            except BaseException:
                pump.end_publication(sequence, False)
                raise
            cdr = msg if isinstance(msg, (bytes, bytearray, memoryview)) else written
            pump.end_publication(sequence, True, cdr)

        return publish_and_record

    def is_own(self, sequence: int, stamp: int, received: bytes | None = None) -> bool:
        return self.pump.is_own(sequence, stamp, received)

    def guard(self) -> None:
        self.pump.guard()
