"""A subscription's own ZeroMQ SUB socket, read and delivered by one thread.

Through the node's shared SUB socket, every message of a queued subscription crossed two
threads: the I/O thread read its four frames (pyzmq releases the GIL around each read) and
handed it to the subscription's delivery thread. At kilohertz rates those hand-overs cost
more than converting the message. A :class:`SubscriptionReader` instead owns a SUB socket
subscribed to its one topic and connected to that topic's publishers, and one thread both
reads and delivers: no hand-over, and each topic has its own TCP connection, so a flooded
topic's back-pressure never holds another topic's messages. That thread is the reader's own,
or, for a native channel, the process's one native loop, which serves every native channel
(``native/loop.py``): a fleet of robots costs no thread per topic. The native loop reads and
publishes the messages itself and runs :meth:`SubscriptionReader.native_turn` only for what it
hands back and for the reader's own share (connections, posted commands, intra-process
messages).

The newest ``size`` messages (and at most ``max_bytes`` of them) wait in the transport's one
:class:`~ros_gz_bridge_py.transport.delivery.DropOldestQueue`; the socket is drained between
deliveries, so when the callback is slower than the publisher the oldest are dropped and
counted, as with ROS "keep last". ZeroMQ sockets are single-threaded: connects and
disconnects from other threads are posted to the reader; local (intra-process) messages go
into its queue; both wake it up.

After a burst of large messages, freed memory goes back to the system (``heap.py``).

A message of the topic that cannot be used (malformed frames, a type the subscription does
not take, over the size limit: ``connections.py``) is told to ``reject``; messages of other
topics that share the topic's name as a prefix (ZeroMQ filters by prefix) are not ours and
are skipped without a word.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import queue
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

import zmq

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.transport.api import MessageInfo, NativeLoop, Rejection
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES, TURN_SLICE
from ros_gz_bridge_py.transport.delivery import (
    MAX_QUEUED_BYTES,
    Delivery,
    DropOldestQueue,
    DropWarning,
    Payload,
    payload_sender,
    payload_size,
)
from ros_gz_bridge_py.transport.heap import BurstTrimmer
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.settings import DEFAULT_HWM, TransportSettings
from ros_gz_bridge_py.transport.zmq.connections import SubConnections
from ros_gz_bridge_py.transport.zmq.hwm import MIN_HWM, hwm_for_bytes
from ros_gz_bridge_py.transport.zmq.sockets import subscriber_socket
from ros_gz_bridge_py.transport.zmq.wire import DATA_FRAMES, Frame, decode_data

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

#: Frames up to this size are copied into ``bytes`` on receipt (cheaper than a view for small
#: ones); larger frames, such as images, are handed on as zero-copy views.
COPY_BELOW = 64 * 1024
#: Cached message infos per (topic, sender, type) frames; cleared beyond this size.
INFO_CACHE_SIZE = 1024
#: Longest poll while idle (s). A close or a posted command wakes the reader at once.
IDLE_POLL = 0.25
#: How many times the payload that lowers a reader's receive HWM it is lowered for.
GROWTH_ROOM = 2
#: ``zmq.POLLIN`` as a plain int: ``&`` with the enum runs Python code (enum.Flag.__and__).
_POLLIN = int(zmq.POLLIN)
#: What a message's (topic, sender, type) frames make of it: what the callback is told, a
#: rejection (reason, detail), or None (another topic's).
Verdict = MessageInfo | tuple[Rejection, str] | None


class SubscriptionReader:
    """The SUB socket and thread of one queued subscription (see the module docstring)."""

    def __init__(
        self,
        context: Any,
        *,
        fqn: str,
        partition: str,
        accepts: Callable[[str, str], bool],
        takes: Callable[[str], bool],
        deliver: Callable[[Frame, MessageInfo], None],
        reject: Callable[[Rejection, str], None],
        size: int,
        settings: TransportSettings,
        count: Callable[..., None],
        on_start: Callable[[], None] | None = None,
        max_bytes: int = MAX_QUEUED_BYTES,
        native: NativeLoop | None = None,
        large_messages: bool = False,
    ) -> None:
        self.fqn = fqn
        self._received = 0
        self._native = native
        self._native_dropped = 0
        self._partition = partition
        self._name = (decompose(fqn) or ("", fqn))[1]
        self._topic_frame = fqn.encode()
        self._accepts = accepts
        self._takes = takes
        self._deliver = deliver
        self._reject = reject
        self._limit = settings.max_message_size
        self._max_bytes = max_bytes
        self._configured_hwm = settings.rcvhwm
        #: The socket's receive HWM now (for the largest message taken, where messages are
        #: large by nature), and the largest payload it holds within max_bytes.
        self._hwm = (
            hwm_for_bytes(settings.max_message_size, max_bytes, settings.rcvhwm)
            if large_messages
            else settings.rcvhwm
        )
        self._watch: int | None = self._watch_size()
        self._pending: DropOldestQueue[Delivery] = DropOldestQueue(
            size, weigh=payload_size, max_bytes=max_bytes, source=payload_sender
        )
        self._count = count
        self._warning = DropWarning(fqn, size, max_bytes)
        self._trimmer = BurstTrimmer()
        self._on_start = on_start
        self._infos: dict[tuple[Frame, Frame, Frame], Verdict] = {}
        self._posted: collections.deque[Callable[[], object]] = collections.deque()
        self._closed = False
        self._context = context
        self._settings = settings
        self._sock, self._connections = self._open_socket()
        self._thread: threading.Thread | None = None
        if native is not None:
            native.watch(self._watch)
            native.attach(self._sock.underlying, self._connections.monitor.underlying, self)
            return
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_fd = self._wake_r.fileno()
        self._wake_w.setblocking(False)
        self._thread = threading.Thread(target=self._run, name=f"gz-sub {self._name}", daemon=True)
        self._thread.start()

    # --- from any thread --------------------------------------------------------------------

    def connect(self, address: str) -> None:
        """Connect to a publisher of the topic (once per address)."""
        self._post(lambda: self._connections.connect(address))

    def leave(self, address: str) -> None:
        """Stop connecting to ``address`` soon: no publisher of the topic is there any more
        (``SubConnections.leave``)."""
        self._post(lambda: self._connections.leave(address))

    @property
    def received(self) -> int:
        """Messages of the topic accepted so far (by the native loop too)."""
        return self._received + (self._native.received if self._native is not None else 0)

    @property
    def dropped(self) -> int:
        """Messages dropped so far, oldest first (by the native loop too)."""
        return self._pending.dropped + self._native_dropped

    def offer(self, payload: Payload, info: MessageInfo) -> int:
        """An intra-process message (from any thread): queued like a received one; returns how
        many older messages it pushed out."""
        if self._closed:
            return 0
        dropped = self._pending.put((bytes(payload), info))
        self._wake()
        return dropped

    def close(self) -> None:
        """Stop after the message being delivered; pending ones are discarded. Idempotent."""
        if self._closed:
            return
        self._closed = True
        if self._native is not None:
            self._native.detach()
            self._release()
            return
        self._wake()
        assert self._thread is not None  # a reader without a native loop has its own
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _post(self, command: Callable[[], object]) -> None:
        if not self._closed:
            self._posted.append(command)
            self._wake()

    def _wake(self) -> None:
        if self._native is not None:
            self._native.wake()
            return
        with contextlib.suppress(OSError):
            self._wake_w.send(b"\0")

    def _open_socket(self) -> tuple[Any, SubConnections]:
        """A SUB socket of the topic with the receive HWM as it is now, and its connections."""
        sock = subscriber_socket(self._context, self._settings, self._hwm)
        sock.setsockopt(zmq.SUBSCRIBE, self._topic_frame)
        connections = SubConnections(
            sock, drain=self._drain, on_refused=self._refused, count=self._count, what=self.fqn
        )
        return sock, connections

    def _release(self) -> None:
        self._connections.close()
        self._sock.close(linger=0)

    # --- the reader thread ------------------------------------------------------------------

    def _run(self) -> None:
        try:
            if self._on_start is not None:
                self._on_start()
            polled, poller = None, zmq.Poller()
            while not self._closed:
                if polled is not self._sock:  # at first, and after a new socket (_payload_grew)
                    polled, poller = self._sock, self._poller()
                try:
                    self._turn(dict(poller.poll(self._poll_timeout())))
                except zmq.ContextTerminated:  # the node went away without closing us
                    return
                except Exception:  # the reader must survive anything, as the I/O thread does
                    self._count("io_errors")
                    _LOG.exception("unexpected error reading %s", self.fqn)
        finally:
            self._release()
            self._wake_r.close()
            self._wake_w.close()

    def _poller(self) -> Any:
        poller = zmq.Poller()
        poller.register(self._sock, zmq.POLLIN)
        poller.register(self._wake_r.fileno(), zmq.POLLIN)
        poller.register(self._connections.monitor, zmq.POLLIN)
        return poller

    # --- the native loop's thread -----------------------------------------------------------

    def native_turn(
        self, unrouted: list[list[Frame]], *, monitor: bool, broken: bool, grown: int = 0
    ) -> float | None:
        """The reader's share of a native channel's work (``NativeHost``): posted commands,
        the frames the loop had no route for, the connections, the messages queued here."""
        native = self._native
        if self._closed or native is None:
            return None
        if broken:  # the context went away without closing us: closed here, as a thread would
            self._count("io_errors")
            _LOG.warning("the socket of %s cannot be read any more; it is closed", self.fqn)
            self._closed = True
            native.detach()
            self._release()
            return None
        while self._posted:
            self._posted.popleft()()
        for frames in unrouted:
            self._judge_for(native, frames)
        dropped = native.dropped - self._native_dropped
        if dropped:
            self._native_dropped += dropped
            self._count("messages_dropped", dropped)
            self._warning.dropped(self.dropped, native.dropped_sender)
        if grown:
            self._payload_grew(grown)
        now = time.monotonic()
        connections = self._connections
        if monitor or connections.is_due(now):
            connections.turn()
        self._deliver_pending()
        if len(self._pending):
            return now  # more to deliver: again at once
        return connections.next_deadline()

    def _judge_for(self, native: NativeLoop, frames: list[Frame]) -> None:
        """A message the native loop had no route for: judged here (the Python reference),
        the route told to the loop, and the message itself delivered through Python."""
        verdict = self._verdict(frames)
        if len(frames) == DATA_FRAMES and (verdict is None or isinstance(verdict, MessageInfo)):
            native.learn(bytes(frames[1]), bytes(frames[3]), take=verdict is not None)
        if isinstance(verdict, MessageInfo):
            self._received += 1
            self._keep((frames[2], verdict))
        elif verdict is not None:
            self._reject(*verdict)

    def _poll_timeout(self) -> int:
        """Milliseconds to wait: none with messages pending, else until the connections
        have something to do, at most IDLE_POLL."""
        if len(self._pending):
            return 0
        wait = IDLE_POLL
        deadline = self._connections.next_deadline()
        if deadline is not None:
            wait = min(wait, max(0.0, deadline - time.monotonic()))
        return int(wait * 1000) + 1

    def _turn(self, ready: dict[Any, int]) -> None:
        """One wake-up: only what ``ready`` (the poll's answer) or a deadline asks for is
        read, so a message costs one poll and its reads (at 1 kHz, every extra system call
        and raised exception was a few percent of the message)."""
        if self._wake_fd in ready:
            with contextlib.suppress(BlockingIOError):
                self._wake_r.recv(4096)
        while self._posted:
            self._posted.popleft()()
        if self._sock in ready:
            self._drain()
        connections = self._connections
        if connections.monitor in ready or connections.is_due(time.monotonic()):
            connections.turn()
        self._deliver_pending()

    def _deliver_pending(self) -> None:
        """Deliver queued messages for up to TURN_SLICE (the socket is drained between)."""
        pending = self._pending
        end = time.monotonic() + TURN_SLICE
        while len(pending) and not self._closed:
            try:
                payload, info = pending.get(block=False)
            except queue.Empty:  # an offer from another thread dropped it first
                break
            self._deliver(payload, info)
            if time.monotonic() >= end:
                return
        if not len(pending):
            self._trimmer.idle()  # memory of a burst of large messages goes back

    def _refused(self, address: str) -> None:
        self._reject(
            Rejection.OVERSIZE,
            f"a message from {address} was larger than {self._limit} bytes "
            "(GZ_TRANSPORT_MAX_MESSAGE_SIZE), or not in ZeroMQ framing: libzmq dropped the "
            "connection before buffering it; reconnecting",
        )

    def _drain(self) -> None:
        sock = self._sock
        for _ in range(TURN_MESSAGES):
            if self._sock is not sock:  # replaced by _payload_grew: read from the new one later
                return
            if not sock.getsockopt(zmq.EVENTS) & _POLLIN:  # cheaper than raising zmq.Again
                return
            frames = receive_message(sock)
            verdict = self._verdict(frames)
            if isinstance(verdict, MessageInfo):
                self._received += 1
                size = len(frames[2])
                self._trimmer.received(size)
                self._keep((frames[2], verdict))
                if self._watch is not None and size > self._watch:
                    self._payload_grew(size)  # reads what waits: after this one, in order
            elif verdict is not None:
                self._reject(*verdict)

    def _watch_size(self) -> int | None:
        """The largest payload the socket's receive HWM holds within ``max_bytes``; None
        where the HWM is as low as it goes."""
        if 0 < self._hwm <= MIN_HWM:
            return None
        return self._max_bytes // (self._hwm if self._hwm > 0 else DEFAULT_HWM)

    def _payload_grew(self, size: int) -> None:
        """A payload of ``size`` bytes would make libzmq's queue in front of ours (RCVHWM
        messages of any size per connection) hold more than ``max_bytes``: the HWM is lowered
        to fit payloads of up to :data:`GROWTH_ROOM` times that size (``hwm.py``; a topic
        whose messages grow by small steps changes socket once per doubling, not at each step)
        on a new socket, connected where the old one was, which replaces it: libzmq applies
        an HWM set on a socket to its open connections too, which then stall for good, or
        crash it while a connection closes (docs/protocol.md, "The receive queue in bytes").
        What the old socket holds is read first (one batch more); what is still on its way
        in its connections is lost, once per lowering. On the socket's thread."""
        hwm = hwm_for_bytes(GROWTH_ROOM * size, self._max_bytes, self._configured_hwm)
        if 0 < self._hwm <= hwm:
            return  # as low already (a size the native pump told before the last lowering)
        self._hwm = hwm
        self._watch = self._watch_size()
        self._replace_socket()
        _LOG.info(
            "%s: a payload of %d bytes: its receive queue now holds %d messages per "
            "publisher (parameter max_queued_bytes, %d bytes); connected anew to %d "
            "publisher(s)",
            self.fqn, size, hwm, self._max_bytes, len(self._connections.connected),
        )  # fmt: skip
        if self._native is not None:
            self._native.watch(self._watch)

    def _replace_socket(self) -> None:
        """A socket with the HWM as it is now replaces the reader's, connected to the same
        publishers (see :meth:`_payload_grew`); a native loop reads the new one."""
        sock, connections = self._open_socket()
        for address in self._connections.connected:
            connections.connect(address)
        if self._native is not None:
            self._native.detach()  # on the loop's thread: at once (its queue is dropped)
        self._drain()
        old_sock, old_connections = self._sock, self._connections
        self._sock, self._connections = sock, connections
        old_connections.close()
        old_sock.close(linger=0)
        if self._native is not None:
            self._native.attach(sock.underlying, connections.monitor.underlying, self)

    def _verdict(self, frames: list[Frame]) -> Verdict:
        """What to do with a message (see :data:`Verdict`); cached per topic, sender, type."""
        key = (frames[0], frames[1], frames[3]) if len(frames) == DATA_FRAMES else None
        if key is not None and key in self._infos:
            return self._infos[key]
        verdict = self._judge(frames)
        if key is not None and all(isinstance(frame, bytes) for frame in key):
            if len(self._infos) >= INFO_CACHE_SIZE:
                self._infos.clear()
            self._infos[key] = verdict
        return verdict

    def _judge(self, frames: list[Frame]) -> Verdict:
        try:
            message = decode_data(frames)
        except RemoteProtocolError as error:
            if bytes(frames[0]) != self._topic_frame:
                self._count("frames_malformed")  # another topic's: not ours to report
                return None
            return Rejection.MALFORMED, f"{error} (from a process that is not Gazebo Transport?)"
        if message.topic != self.fqn:
            return None
        if not self._accepts(message.sender, message.msg_type):
            if self._takes(message.msg_type):
                return None  # the other spelling of a message already taken (docs/protocol.md §9)
            return (
                Rejection.WRONG_TYPE,
                f"the publisher at {message.sender} sends {message.msg_type}",
            )
        return MessageInfo(
            self._name, message.msg_type, self._partition, message.sender, intra_process=False
        )

    def _keep(self, item: Delivery) -> None:
        """Queue ``item``, dropping the oldest beyond ``size`` messages or ``max_bytes``."""
        pending = self._pending
        dropped = pending.put(item)
        if dropped:
            self._count("messages_dropped", dropped)
            sender = pending.dropped_source
            self._warning.dropped(self.dropped, str(sender) if sender is not None else "")


def receive_message(sock: Any) -> list[Frame]:
    """One multipart message, frame by frame (much cheaper than ``recv_multipart``).

    Raises:
        zmq.Again: no message is waiting.
    """
    frames: list[Frame] = []
    while True:
        frame = sock.recv(zmq.NOBLOCK, copy=False)
        frames.append(frame.bytes if len(frame) < COPY_BELOW else frame.buffer)
        if not frame.more:
            return frames
