"""The two drivers of a queued subscription's socket owner (``socket_owner.py``): a reader with
a thread of its own, or the native Gazebo -> ROS loop (docs/threads.md).

Through the node's shared SUB socket, every message of a queued subscription crossed two
threads: the I/O thread read its four frames (pyzmq releases the GIL around each read) and
handed it to the subscription's delivery thread. At kilohertz rates those hand-overs cost
more than converting the message. A queued subscription instead has a SUB socket of its own,
read and delivered by one thread, the one its driver gives it:

- :class:`SubscriptionReader`: a thread of its own (``gz-sub <topic>``) polls the socket,
  reads what came and delivers it;
- :class:`NativeReader`: the process's one native Gazebo -> ROS loop (``native/loop.py``)
  reads and publishes the messages itself, so that a fleet of robots costs no thread per topic,
  and runs :meth:`NativeReader.native_turn` only for what it hands back and for the owner's own
  share (connections, posted commands, intra-process messages). A topic of small messages is
  read through the socket the node's native channels share (``shared_sub.py``), until its
  payloads outgrow it; the others through a socket owner of their own.

Either way, the newest ``size`` messages (and at most ``max_bytes`` of them) the driver delivers
itself wait in the transport's one :class:`~ros_gz_bridge_py.transport.delivery.DropOldestQueue`;
the socket is read between deliveries, so when the callback is slower than the publisher the
oldest are dropped and counted, as with ROS "keep last". Local (intra-process) messages go into
the same queue (:meth:`offer`) and wake the driver. After a burst of large messages, freed
memory goes back to the system (``heap.py``).
"""

from __future__ import annotations

import contextlib
import logging
import queue
import socket
import threading
import time
from collections.abc import Callable
from typing import Any, TypedDict, Unpack

import zmq

from ros_gz_bridge_py.libc import name_os_thread
from ros_gz_bridge_py.transport.api import MessageInfo, NativeLoop
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES, TURN_SLICE
from ros_gz_bridge_py.transport.delivery import (
    Delivery,
    DropOldestQueue,
    DropWarning,
    Payload,
    payload_sender,
    payload_size,
)
from ros_gz_bridge_py.transport.heap import BurstTrimmer
from ros_gz_bridge_py.transport.zmq.shared_sub import SharedSub
from ros_gz_bridge_py.transport.zmq.socket_owner import SocketOwner, Topic, Verdicts, watch_size
from ros_gz_bridge_py.transport.zmq.wire import DATA_FRAMES, Frame

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
#: Where a driver's messages go: the subscription's callback.
Deliver = Callable[[Frame, MessageInfo], None]
Hook = Callable[[], None]


class Driven(TypedDict):
    """What each driver is made with besides its owner's topic: the callback, and how many
    messages its queue keeps."""

    deliver: Deliver
    size: int


#: Longest poll of a reader's own thread while idle (s). A close or a posted command wakes it.
IDLE_POLL = 0.25


class _Driver:
    """What both drivers share: the owner, the queue of the messages the driver delivers, and
    closing (see the module docstring)."""

    #: The topic's own socket (None: none, the topic is read through a shared one).
    _owner: SocketOwner | None

    def __init__(self, context: Any, topic: Topic, *, deliver: Deliver, size: int) -> None:
        self.fqn = topic.fqn
        self._context = context
        self._topic = topic
        self._received = 0
        self._deliver = deliver
        self._reject = topic.reject
        self._pending: DropOldestQueue[Delivery] = DropOldestQueue(
            size, weigh=payload_size, max_bytes=topic.max_bytes, source=payload_sender
        )
        self._count = topic.count
        self._warning = DropWarning(topic.fqn, size, topic.max_bytes)
        self._trimmer = BurstTrimmer()
        self._closed = False

    def _own_socket(self, largest: int = 0) -> SocketOwner:
        """A socket of the topic's own (``largest``: a payload size its queue must hold)."""
        return SocketOwner(
            self._context,
            self._topic,
            keep=self._keep,
            wake=self._wake,
            replacing=self._replacing,
            replaced=self._replaced,
            largest=largest,
        )

    # --- from any thread --------------------------------------------------------------------

    def connect(self, address: str) -> None:
        """Connect to a publisher of the topic (once per address)."""
        owner = self._owner
        if not self._closed and owner is not None:
            owner.post(lambda: owner.connections.connect(address))

    def leave(self, address: str) -> None:
        """Stop connecting to ``address`` soon: no publisher of the topic is there any more
        (``SubConnections.leave``)."""
        owner = self._owner
        if not self._closed and owner is not None:
            owner.post(lambda: owner.connections.leave(address))

    @property
    def received(self) -> int:
        """Messages of the topic accepted so far."""
        return self._received

    @property
    def dropped(self) -> int:
        """Messages dropped so far, oldest first."""
        return self._pending.dropped

    def offer(self, payload: Payload, info: MessageInfo) -> int:
        """An intra-process message (from any thread): queued like a received one; returns how
        many older messages it pushed out."""
        if self._closed:
            return 0
        dropped = self._pending.put((bytes(payload), info))
        self._wake()
        return dropped

    # --- the driver's hooks -----------------------------------------------------------------

    def _wake(self) -> None:
        raise NotImplementedError

    def _replacing(self) -> None:
        """The owner is about to replace its socket (on the owner's thread)."""

    def _replaced(self) -> None:
        """The owner replaced its socket (on the owner's thread)."""

    # --- the owner's thread -----------------------------------------------------------------

    def _keep(self, payload: Frame, info: MessageInfo) -> None:
        """Queue a message, dropping the oldest beyond ``size`` messages or ``max_bytes``."""
        self._received += 1
        self._trimmer.received(len(payload))
        pending = self._pending
        dropped = pending.put((payload, info))
        if dropped:
            self._count("messages_dropped", dropped)
            sender = pending.dropped_source
            self._warning.dropped(self.dropped, str(sender) if sender is not None else "")

    def _deliver_pending(self) -> None:
        """Deliver queued messages for up to TURN_SLICE (the socket is read between)."""
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


class SubscriptionReader(_Driver):
    """A socket owner read and delivered by a thread of its own (the Python path)."""

    def __init__(
        self, context: Any, topic: Topic, *, on_start: Hook | None = None, **driver: Unpack[Driven]
    ) -> None:
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._wake_fd = self._wake_r.fileno()
        super().__init__(context, topic, **driver)
        self._owner: SocketOwner = self._own_socket()
        self._on_start = on_start
        name = f"gz-sub {self._owner.name}"
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop after the message being delivered; pending ones are discarded. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._wake()
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_w.send(b"\0")

    def _run(self) -> None:
        owner = self._owner
        name_os_thread(self._thread.name)
        try:
            if self._on_start is not None:
                self._on_start()
            polled, poller = None, zmq.Poller()
            while not self._closed:
                if polled is not owner.sock:  # at first, and after a new socket (owner.grew)
                    polled, poller = owner.sock, self._poller()
                try:
                    self._turn(dict(poller.poll(self._poll_timeout())))
                except zmq.ContextTerminated:  # the node went away without closing us
                    return
                except Exception:  # the reader must survive anything, as the I/O thread does
                    self._count("io_errors")
                    _LOG.exception("unexpected error reading %s", self.fqn)
        finally:
            owner.release()
            self._wake_r.close()
            self._wake_w.close()

    def _poller(self) -> Any:
        poller = zmq.Poller()
        poller.register(self._owner.sock, zmq.POLLIN)
        poller.register(self._wake_fd, zmq.POLLIN)
        poller.register(self._owner.connections.monitor, zmq.POLLIN)
        return poller

    def _poll_timeout(self) -> int:
        """Milliseconds to wait: none with messages pending, else until the connections
        have something to do, at most IDLE_POLL."""
        if len(self._pending):
            return 0
        wait = IDLE_POLL
        deadline = self._owner.connections.next_deadline()
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
        owner = self._owner
        owner.run_posted()
        if owner.sock in ready:
            owner.read(TURN_MESSAGES)
        owner.turn_connections(time.monotonic(), monitor=owner.connections.monitor in ready)
        self._deliver_pending()


class NativeReader(_Driver):
    """A subscription read by a native loop (``NativeLoop``, the process's Gazebo -> ROS loop),
    its share run on the loop's thread (``NativeHost``): through the node's shared socket
    (``shared``: ``shared_sub.py``) until its payloads outgrow the shared queue's byte budget,
    then, as a topic large by nature from the start, through a socket owner of its own."""

    def __init__(
        self,
        context: Any,
        topic: Topic,
        *,
        native: NativeLoop,
        shared: SharedSub | None,
        **driver: Unpack[Driven],
    ) -> None:
        self._native = native
        self._native_dropped = 0
        self.topic_frame = topic.fqn.encode()
        super().__init__(context, topic, **driver)
        self._verdicts = Verdicts(topic)
        # A topic another channel reads through the shared socket gets a socket of its own.
        self._shared = shared if shared is not None and shared.claim(self.topic_frame) else None
        self._owner: SocketOwner | None = None
        if self._shared is not None:
            native.watch(watch_size(self._shared.settings.shared_rcvhwm, topic.max_bytes))
            self._shared.add(self, native)
        else:
            self._attach(self._own_socket())

    @property
    def received(self) -> int:
        """Messages of the topic accepted so far, by the native loop too."""
        return self._received + self._native.received

    @property
    def dropped(self) -> int:
        """Messages dropped so far, oldest first, by the native loop too."""
        return self._pending.dropped + self._native_dropped

    def connect(self, address: str) -> None:
        shared = self._shared
        if shared is None:
            super().connect(address)
        elif not self._closed:
            shared.connect(address, self)

    def leave(self, address: str) -> None:
        shared = self._shared
        if shared is None:
            super().leave(address)
        elif not self._closed:
            shared.leave(address, self)

    def close(self) -> None:
        """Off the loop, then the socket or the topic's subscription goes; pending messages
        are discarded. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._native.detach()
        if self._owner is not None:
            self._owner.release()
        if self._shared is not None:
            self._shared.remove(self)

    # --- the shared socket's (shared_sub.py), on the loop's thread ---------------------------

    def take(self, frames: list[Frame]) -> None:
        """A message of the topic read from the shared socket by Python (before a
        disconnect)."""
        verdict = self._verdicts.verdict(frames)
        if isinstance(verdict, MessageInfo):
            self._keep(frames[2], verdict)
        elif verdict is not None:
            self._reject(*verdict)

    def refused(self, address: str) -> None:
        """libzmq refused a message from ``address`` for its size (perhaps another topic's)."""
        self._reject(*self._verdicts.refused(address))

    # --- the driver's hooks -----------------------------------------------------------------

    def _wake(self) -> None:
        self._native.wake()

    def _replacing(self) -> None:
        self._native.detach()  # on the loop's thread: at once (its queue is dropped)

    def _replaced(self) -> None:
        if self._owner is not None:
            self._attach(self._owner)

    def _attach(self, owner: SocketOwner) -> None:
        self._owner = owner
        self._native.watch(owner.watch)
        self._native.attach(owner.sock.underlying, owner.connections.monitor.underlying, self)

    def _move_out(self, size: int) -> None:
        """A payload of ``size`` bytes: the shared socket's queue (RCVHWM messages of any size
        per publisher) would hold more than ``max_bytes`` of them, so the topic moves to a socket
        of its own whose receive HWM fits it (``SocketOwner.grew``), connected where the topic's
        publishers are. What is still on its way through the shared socket is lost, once."""
        shared = self._shared
        if shared is None:
            return
        addresses = shared.addresses(self)
        self._native.detach()
        self._shared = None
        shared.remove(self)
        owner = self._own_socket(largest=size)
        for address in addresses:
            owner.connections.connect(address)
        self._attach(owner)
        _LOG.info(
            "%s: a payload of %d bytes: the topic leaves the shared socket for one of its own "
            "(parameter max_queued_bytes, %d bytes); connected to %d publisher(s)",
            self.fqn, size, self._topic.max_bytes, len(addresses),
        )  # fmt: skip

    # --- the loop's thread --------------------------------------------------------------------

    def native_turn(
        self, unrouted: list[list[Frame]], *, monitor: bool, broken: bool, grown: int = 0
    ) -> float | None:
        """The topic's share of a native channel's work (``NativeHost``): posted commands,
        the frames the loop had no route for, the connections of its own socket, the messages
        queued here."""
        native, owner = self._native, self._owner
        if self._closed:
            return None
        if broken:  # the context went away without closing us: closed here, as a thread would
            self._count("io_errors")
            _LOG.warning("the socket of %s cannot be read any more; it is closed", self.fqn)
            self.close()
            return None
        if owner is not None:
            owner.run_posted()
        for frames in unrouted:
            self._judge(frames)
        dropped = native.dropped - self._native_dropped
        if dropped:
            self._native_dropped += dropped
            self._count("messages_dropped", dropped)
            self._warning.dropped(self.dropped, native.dropped_sender)
        if grown and owner is None:
            self._move_out(grown)
        elif grown and owner is not None:
            owner.grew(grown)
        now = time.monotonic()
        owner = self._owner
        if owner is not None:
            owner.turn_connections(now, monitor=monitor)
        self._deliver_pending()
        if len(self._pending):
            return now  # more to deliver: again at once
        return owner.connections.next_deadline() if owner is not None else None

    def _judge(self, frames: list[Frame]) -> None:
        """A message the native loop had no route for: judged here (the Python reference),
        the route told to the loop, and the message itself delivered here.

        A route names a sender and a type, and the loop follows it for the topic's own frames
        only: it is learned from those alone. A topic the topic's name prefixes comes through
        the socket too (ZeroMQ subscribes by prefix), often from the same publisher with the
        same type (``/model/x/pose`` and ``/model/x/pose_static``): its verdict (None, not
        ours) taught as a route would have the loop skip the topic's own messages."""
        verdict = self._verdicts.verdict(frames)
        if (
            len(frames) == DATA_FRAMES
            and (verdict is None or isinstance(verdict, MessageInfo))
            and bytes(frames[0]) == self.topic_frame
        ):
            self._native.learn(bytes(frames[1]), bytes(frames[3]), take=verdict is not None)
        if isinstance(verdict, MessageInfo):
            self._keep(frames[2], verdict)
        elif verdict is not None:
            self._reject(*verdict)
