"""The ZeroMQ Gazebo Transport node: sockets and one I/O thread around the sans-IO core.

Each :class:`ZmqGzNode` is a full gz participant with its own process UUID (two nodes in one
Python process look like two processes on the wire), with two discovery engines (topics and
services, :mod:`~.discovery`) and the sockets of docs/protocol-zmq-discovery.md §2.1
(:mod:`~.sockets`). The service side is :class:`~.services.ServiceRouter`, received data is routed
by :mod:`~.routes`, and what discovery knows is answered by :class:`~.node_graph.ZmqGraphView`.

Threading model: one I/O thread (``gz-io``) owns the discovery engines and every socket
except PUB, the queued subscriptions' own SUB sockets and the one the native channels of small
messages share (:mod:`~.shared_sub`); other threads post commands to it
(and wait for a result where there is one). Publishing threads use PUB under a lock. Callbacks
of subscriptions without a queue, service handlers and ``request_async`` callbacks run on the
I/O thread, so they must be quick; a queued subscription reads its own SUB socket on its own
thread, or the native Gazebo -> ROS loop reads it, or the shared one, on its (:mod:`~.reader`).
Bad network input never raises out of the I/O thread: it is counted in ``stats`` and logged at
debug level; a raising callback is logged and counted.
"""

from __future__ import annotations

import collections
import concurrent.futures
import contextlib
import logging
import threading
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any, TypeVar, cast

import zmq

from ros_gz_bridge_py.errors import RemoteProtocolError, TransportError
from ros_gz_bridge_py.transport.api import Scope, ServiceHandler
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES
from ros_gz_bridge_py.transport.delivery import Payload
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.settings import DEFAULT_HWM
from ros_gz_bridge_py.transport.zmq.discovery import DiscoveryEngine
from ros_gz_bridge_py.transport.zmq.discovery_events import (
    Event,
    PublisherAdded,
    PublisherRemoved,
    SubscriberAdded,
    SubscriberRemoved,
)
from ros_gz_bridge_py.transport.zmq.endpoints import ZmqPublisher, ZmqServiceOffer, ZmqSubscription
from ros_gz_bridge_py.transport.zmq.hwm import hwm_for_bytes
from ros_gz_bridge_py.transport.zmq.intake import DataIntake, Reader
from ros_gz_bridge_py.transport.zmq.node_graph import ZmqGraphView
from ros_gz_bridge_py.transport.zmq.routes import DataRouter
from ros_gz_bridge_py.transport.zmq.services import PendingCall, RouterSockets, ServiceRouter
from ros_gz_bridge_py.transport.zmq.socket_owner import receive_message
from ros_gz_bridge_py.transport.zmq.sockets import open_sockets, publisher_socket
from ros_gz_bridge_py.transport.zmq.udp import DiscoverySocket, determine_host
from ros_gz_bridge_py.transport.zmq.wire import (
    Frame,
    MessagePublisher,
    PublisherRecord,
    ServicePublisher,
)

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
T = TypeVar("T")

#: Poll timeout while a retry is pending, and the longest poll otherwise (§2.5: 250 ms).
RETRY_POLL = 0.005
MAX_POLL = 0.25


class ZmqGzNode(ZmqGraphView):
    """A Gazebo Transport node speaking the ZeroMQ protocol (gz-transport wire version 10).

    Made as every :class:`GzNode` is; raises :class:`LocalProtocolError` for an invalid
    partition or namespace and :class:`TransportError` when the sockets cannot be opened.
    """

    subscription_class = ZmqSubscription
    call_class = PendingCall
    runs_native_loops = True

    # --- sockets and the I/O thread -------------------------------------------------------

    def _open(self) -> None:
        #: The node id of the announcements of our publishers under their other spelling
        #: (gz peers keep one record per node and address, so it must differ).
        self.respelled_node_uuid = str(uuid.uuid4())
        self.host = determine_host(self.settings.ip, self.settings.multicast_ip)
        # I/O thread only: the per-message fast path takes no lock.
        self._router = DataRouter(self.subscriptions, self.partition)
        self._commands: collections.deque[Callable[[], None]] = collections.deque()
        self._io_thread: threading.Thread | None = None
        self._stopping = False
        self._spellings_version = -1
        #: Publishers with a socket of their own (a native loop may send on it).
        self._own_socket_publishers: set[ZmqPublisher] = set()
        self._io = open_sockets(self.settings, self.host, self.count)
        # Connections to publishers, and the queued subscriptions' readers (intake.py).
        self._intake = DataIntake(
            self, self._io, lambda: self._read_frames(self._io.sub, self._router.on_data)
        )
        self.host = self._io.host
        self.pub_address = self._io.address(self._io.pub)
        self.replier_address = self._io.address(self._io.replier)
        self.response_address = self._io.address(self._io.responses)
        now = time.monotonic()
        engine_args: dict[str, Any] = {
            "local_ips": {self.host},
            "relays": self.settings.relays,
            "legacy_spelling": self.settings.legacy_spelling,
        }
        self._msg = DiscoveryEngine(
            self.process_uuid, now, respelled_nodes=(self.respelled_node_uuid,), **engine_args
        )
        self._srv = DiscoveryEngine(self.process_uuid, now, **engine_args)
        sockets = RouterSockets(
            self._srv, lambda out: self._datagrams(self._io.srv_udp, out), self._io.requester,
            self._io.replier, self.response_address, self._io.response_id, self.node_uuid,
        )  # fmt: skip
        self._services = ServiceRouter(sockets, self.count, self.call_handler, self.finish_call)
        self._io_thread = threading.Thread(target=self._io_main, name="gz-io", daemon=True)
        self._io_thread.start()

    def _shutdown(self) -> None:
        """UNADVERTISE, END_CONNECTION and BYE, then stop the I/O thread."""
        with contextlib.suppress(TransportError):
            self._call(self._say_goodbye)
        self._stopping = True
        self._io.wake()
        if self._io_thread is not None and self._io_thread is not threading.current_thread():
            self._io_thread.join()

    def _say_goodbye(self) -> None:
        for subs in list(self._subscriptions.values()):
            for index, sub in enumerate(subs):
                self._end_subscription(cast(ZmqSubscription, sub), last=index == len(subs) - 1)
        for engine, udp in ((self._msg, self._io.msg_udp), (self._srv, self._io.srv_udp)):
            self._datagrams(udp, engine.bye())
        self._services.cancel_all()

    def _release(self) -> None:
        # A native loop may still send on a publisher's own socket: it stops before the
        # context (and every socket with it) goes.
        for publisher in list(self._own_socket_publishers):
            publisher.stop_senders()
        self._intake.close()
        self._io.release()

    def _post(self, command: Callable[[], None]) -> None:
        self._check_open()
        self._commands.append(command)
        self._io.wake()

    def _soon(self, command: Callable[[], None]) -> None:
        """Run ``command`` on the I/O thread without waiting for it: a new publisher's
        announcements need no answer, and a caller that waited for an I/O thread busy with
        traffic made every channel's creation wait a scheduling round (issue 23)."""
        if threading.current_thread() is self._io_thread:
            command()
        else:
            self._post(command)

    def _call(self, function: Callable[[], T]) -> T:
        """Run ``function`` on the I/O thread and return its result."""
        if threading.current_thread() is self._io_thread:
            return function()
        future: concurrent.futures.Future[T] = concurrent.futures.Future()

        def command() -> None:
            try:
                future.set_result(function())
            except Exception as error:  # handed to the caller
                future.set_exception(error)

        self._post(command)
        return future.result()

    def _on_node_thread(self) -> bool:
        return threading.current_thread() is self._io_thread

    def _add_stats(self, counts: dict[str, int]) -> dict[str, int]:
        """The I/O thread's and the readers' received counts, and the discovery counters."""
        counts["messages_received"] = self._router.received + self._intake.received
        return super()._add_stats(counts)

    # --- topics -----------------------------------------------------------------------------

    def _open_publisher(
        self, topic: str, fqn: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """Announce ``topic`` under each spelling; re-announced every second (§2.5). With
        ``own_socket``, from a PUB socket of the publisher's own, at its own address (a record
        names the address subscribers connect to, docs/protocol-zmq-data.md §2.8.1); with
        ``queue_bytes`` too, and that socket's SNDHWM set for it before the socket is bound
        (§2.8.8)."""
        sock = None
        sndhwm = self.settings.sndhwm
        if queue_bytes > 0:
            sndhwm = hwm_for_bytes(self.settings.max_message_size, queue_bytes, sndhwm)
        if own_socket or queue_bytes > 0:
            sock = publisher_socket(self._io.context, self._io.host, self.settings, sndhwm)
        address = self.pub_address if sock is None else self._io.address(sock)
        nodes = (self.node_uuid, self.respelled_node_uuid)
        records = tuple(
            PublisherRecord(
                fqn, address, self.process_uuid, node, Scope.ALL, MessagePublisher(name)
            )
            for name, node in zip(self.names_of(msg_type), nodes, strict=False)
        )
        publisher = ZmqPublisher(
            self, topic, fqn, msg_type, records, sock=sock, send_queue=sndhwm or DEFAULT_HWM
        )
        if sock is not None:
            self._own_socket_publishers.add(publisher)

        def command() -> None:
            for record in records:
                self._datagrams(self._io.msg_udp, self._msg.advertise(record))

        self._soon(command)
        return publisher

    def _close_publisher(self, publisher: Publisher) -> None:
        zmq_publisher = cast(ZmqPublisher, publisher)
        records = zmq_publisher.records

        def command() -> None:
            for record in records:
                self._datagrams(self._io.msg_udp, self._msg.unadvertise(record))
            self._update_subscribers(publisher.fqn)

        with contextlib.suppress(TransportError):
            self._call(command)
        if zmq_publisher.sock is not None:
            self._own_socket_publishers.discard(zmq_publisher)
            zmq_publisher.sock.close(linger=0)

    def _send(self, publisher: Publisher, wire_type: str, payload: Payload) -> None:
        """The four data frames on the PUB socket (§2.8.2), from the publishing thread."""
        zmq_publisher = cast(ZmqPublisher, publisher)
        topic, sender, _, type_frame = zmq_publisher.wire_frames[wire_type]
        if zmq_publisher.sender is not None:  # a native loop's socket
            zmq_publisher.sender(type_frame, payload)
            return
        own = zmq_publisher.sock
        send = self._io.pub.send if own is None else own.send
        # A socket of the publisher's own is used by one thread (see advertise); the lock
        # still keeps the send from racing with the node's close.
        with self._io.pub_lock:
            if self.closed:
                return
            try:  # frame by frame: much cheaper than send_multipart for small messages
                send(topic, zmq.SNDMORE)
                send(sender, zmq.SNDMORE)
                send(payload, zmq.SNDMORE, copy=not isinstance(payload, bytes))
                send(type_frame)
            except zmq.ZMQError as error:
                self.count("send_failures")
                _LOG.debug("publish on %s failed: %s", publisher.topic, error)

    def _open_delivery(
        self, sub: Subscription, size: int, on_start: Callable[[], None] | None, max_bytes: int
    ) -> Reader:
        """A queued subscription reads its topic's SUB socket on its own thread (reader.py)."""
        return self._intake.open_reader(sub, size, on_start, max_bytes)

    def _open_subscription(self, sub: Subscription) -> None:
        # Waited for: whether the shared socket subscribes to the topic depends on the topic's
        # other subscriptions as they stand when this one starts.
        self._call(lambda: self._start_subscription(cast(ZmqSubscription, sub)))

    def _start_subscription(self, sub: ZmqSubscription) -> None:
        """§2.8.1 steps 2 and 4-5 for a new local subscription."""
        fqn = sub.fqn
        self._router.clear()
        others = [s for s in self.subscriptions(fqn) if s is not sub]
        if not sub.reads_own_socket() and all(s.delivery is not None for s in others):
            self._io.sub.setsockopt(zmq.SUBSCRIBE, fqn.encode())
        sub.record = PublisherRecord(
            fqn, self.pub_address, self.process_uuid, self.node_uuid, Scope.ALL,
            MessagePublisher(sub.msg_type, ctrl=""),
        )  # fmt: skip
        self._msg.add_local_subscriber(sub.record)
        self._datagrams(self._io.msg_udp, self._msg.subscribe(fqn))
        for record in self._msg.remote_publishers(fqn):
            self._connect_publisher(record, [sub])

    def _close_subscription(self, sub: Subscription, *, last: bool) -> None:
        if sub.delivery is not None:
            self._intake.close_reader(cast(Reader, sub.delivery))
        with contextlib.suppress(TransportError):
            self._call(lambda: self._end_subscription(cast(ZmqSubscription, sub), last=last))

    def _end_subscription(self, sub: ZmqSubscription, *, last: bool) -> None:
        fqn = sub.fqn
        self._router.clear()
        if sub.record is not None:
            self._msg.remove_local_subscriber(sub.record)
        remaining = [s for s in self.subscriptions(fqn) if s is not sub]
        if not sub.reads_own_socket() and all(s.delivery is not None for s in remaining):
            self._io.sub.setsockopt(zmq.UNSUBSCRIBE, fqn.encode())
        if not last:
            return
        processes = [r.process_uuid for r in self._msg.remote_publishers(fqn)]
        self._datagrams(
            self._io.msg_udp, self._msg.disconnect(fqn, self.node_uuid, self.pub_address, processes)
        )

    def _connect_publisher(self, record: PublisherRecord, subs: Sequence[Subscription]) -> None:
        """§2.8.1 steps 4-5: connect once per address, NEW_CONNECTION if a subscription takes
        the record (docs/protocol-lines.md §9). Queued subscriptions connect their own sockets."""
        if not self._intake.connect(record, subs):
            return
        taking = [sub for sub in subs if sub.take(record.address, record.msg_type)]
        if taking:
            self._datagrams(self._io.msg_udp, self._msg.connect(record, self.node_uuid))

    # --- services ---------------------------------------------------------------------------

    def _open_offer(
        self, service: str, fqn: str, types: tuple[str, str], handler: ServiceHandler
    ) -> ServiceOffer:
        """Provide ``service``; announced on the service port (§2.9.1)."""
        record = PublisherRecord(
            fqn, self.replier_address, self.process_uuid, self.node_uuid, Scope.ALL,
            srv=ServicePublisher(self._io.replier_id, *types),
        )  # fmt: skip
        offer = ZmqServiceOffer(self, service, record, types, handler)
        self._call(lambda: self._services.add_offer(offer))
        return offer

    def _close_offer(self, offer: ServiceOffer) -> None:
        with contextlib.suppress(TransportError):
            self._call(lambda: self._services.remove_offer(cast(ZmqServiceOffer, offer)))

    def _start_call(self, call: PendingCall) -> None:
        """``call``'s callback runs exactly once on the I/O thread."""
        self._post(lambda: self._services.start_call(call))

    # --- the I/O thread ---------------------------------------------------------------------

    def _io_main(self) -> None:
        poller = zmq.Poller()
        poller.register(self._io.wake_r.fileno(), zmq.POLLIN)
        for udp in (self._io.msg_udp, self._io.srv_udp):
            poller.register(udp.fileno(), zmq.POLLIN)
        for sock in (self._io.sub, self._io.replier, self._io.responses):
            poller.register(sock, zmq.POLLIN)
        poller.register(self._intake.shared.monitor, zmq.POLLIN)
        if self._io.zap is not None:
            poller.register(self._io.zap.socket, zmq.POLLIN)
        while not self._stopping:
            try:
                ready = dict(poller.poll(int(self._poll_timeout() * 1000)))
                self._io_turn(ready)
            except Exception:  # the I/O thread must survive anything
                self.count("io_errors")
                _LOG.exception("unexpected error in the Gazebo Transport I/O thread")

    def _poll_timeout(self) -> float:
        now = time.monotonic()
        if self._services.retrying or self._commands:
            return RETRY_POLL if self._services.retrying else 0.0
        deadline = min(self._msg.next_deadline(), self._srv.next_deadline(), now + MAX_POLL)
        deadline = min(deadline, self._intake.shared.next_deadline() or deadline)
        return max(0.0, self._services.next_deadline(deadline) - now)

    def _io_turn(self, ready: dict[Any, int]) -> None:
        if self._io.wake_r.fileno() in ready:
            with contextlib.suppress(BlockingIOError):
                self._io.wake_r.recv(4096)
        while self._commands:
            self._commands.popleft()()
        for udp, engine in ((self._io.msg_udp, self._msg), (self._io.srv_udp, self._srv)):
            if udp.fileno() in ready:
                self._read_discovery(udp, engine)
        handlers = (
            (self._io.sub, self._router.on_data),
            (self._io.replier, self._services.on_request),
            (self._io.responses, self._services.on_response),
        )
        for sock, handler in handlers:
            if sock in ready:
                self._read_frames(sock, handler)
        if self._io.zap is not None and self._io.zap.socket in ready:
            self._io.zap.handle()
        now = time.monotonic()
        self._intake.shared.turn(now)
        for udp, engine in ((self._io.msg_udp, self._msg), (self._io.srv_udp, self._srv)):
            out, events = engine.tick(now)
            self._datagrams(udp, out)
            self._handle_events(engine, events)
        self._services.turn(now)

    def _read_discovery(self, udp: DiscoverySocket, engine: DiscoveryEngine) -> None:
        for _ in range(TURN_MESSAGES):
            received = udp.receive()
            if received is None:
                break
            out, events = engine.datagram_received(*received, time.monotonic())
            self._datagrams(udp, out)
            self._handle_events(engine, events)
        spellings = self._msg.spellings
        if spellings.version != self._spellings_version:
            self._spellings_version = spellings.version
            self.subscriber_book.set_spellings(spellings.snapshot())

    def _read_frames(self, sock: Any, handler: Callable[[list[Frame]], None]) -> None:
        for _ in range(TURN_MESSAGES):
            try:
                frames = receive_message(sock)
            except zmq.Again:
                return
            try:
                handler(frames)
            except RemoteProtocolError as error:
                self.count("frames_malformed")
                _LOG.debug("dropped ZMQ message: %s", error)

    def _handle_events(self, engine: DiscoveryEngine, events: list[Event]) -> None:
        if not events:
            return
        for event in events:
            if engine is self._msg:
                self._handle_topic_event(event)
            elif isinstance(event, PublisherAdded):
                self._services.provider_found(event.record.topic)
            elif isinstance(event, PublisherRemoved):
                self._services.provider_gone(event.record.address)
        self.graph_changed()

    def _handle_topic_event(self, event: Event) -> None:
        if isinstance(event, PublisherAdded):
            subs = self.subscriptions(event.record.topic)
            if subs:
                self._connect_publisher(event.record, subs)
        elif isinstance(event, PublisherRemoved):
            self._intake.publisher_gone(event.record, list(self._msg.all_publishers()))
        elif isinstance(event, SubscriberAdded | SubscriberRemoved):
            self._update_subscribers(event.topic)
