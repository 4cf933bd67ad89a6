"""The ZeroMQ Gazebo Transport node: sockets and one I/O thread around the sans-IO core.

Each :class:`ZmqNode` is a full gz participant with its own process UUID (two nodes in one
Python process look like two processes on the wire). It owns two UDP discovery sockets (msg
and srv port, each with its own :class:`DiscoveryEngine`) and the five ZMQ sockets of
gz-transport-protocol.md §2.1: PUB (bound), SUB (connected to publishers), replier ROUTER
(bound), requester ROUTER (connected to providers), responseReceiver ROUTER (bound). The
service side (offers, calls, retried ROUTER sends) is :class:`~.zmq_services.ServiceRouter`.

Threading model:

* One I/O thread (``gz-io``) owns the discovery engines, the UDP sockets and every ZMQ socket
  except PUB and the queued subscriptions' own SUB sockets. Calls from other threads
  (advertise, subscribe, close, listings, requests) are posted to it as commands and, where
  they return something, waited for.
* The PUB socket is used directly by the publishing thread, under a lock (ZMQ sockets are not
  thread-safe; the lock also gives the memory barrier between threads).
* Callbacks: subscription callbacks with ``queue_size=None``, service handlers and
  ``request_async`` callbacks run on the I/O thread, so they must be quick; with
  ``queue_size=N`` a subscription has its own SUB socket and thread, which reads the topic's
  messages and runs the callback (:mod:`~.zmq_reader`; the I/O thread only tells it which
  publishers to connect to). Intra-process
  messages are handed over by the publishing thread (posted to the subscription's reader, or
  to the callback when there is no queue), as gz-transport does.
* Publishing, ``has_connections``, ``stats`` and every public method are thread-safe;
  ``request`` must not be called from the I/O thread (it would wait for itself).
* Bad network input never raises out of the I/O thread: it is counted in ``stats`` and logged
  at debug level on ``ros_gz_bridge_py.transport``. A raising callback is logged and counted.
"""

from __future__ import annotations

import collections
import concurrent.futures
import contextlib
import logging
import socket
import threading
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import zmq

from ros_gz_bridge_py.errors import RemoteProtocolError, TransportError
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, spellings
from ros_gz_bridge_py.transport.api import (
    PUBLISHER,
    SUBSCRIBER,
    GraphEndpoint,
    MessageInfo,
    Node,
    ReplyCallback,
    Scope,
    ServiceHandler,
    TopicInfo,
    TransportStats,
)
from ros_gz_bridge_py.transport.names import decompose, fully_qualified_name
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.wire_types import SubscriberBook, WireTypeCache
from ros_gz_bridge_py.transport.zmq.discovery import (
    INIT_DELAY,
    DiscoveryEngine,
    Event,
    Outgoing,
    PublisherAdded,
    SubscriberAdded,
    SubscriberRemoved,
)
from ros_gz_bridge_py.transport.zmq.endpoints import ZmqPublisher, ZmqServiceOffer, ZmqSubscription
from ros_gz_bridge_py.transport.zmq.reader import SubscriptionReader, receive_message
from ros_gz_bridge_py.transport.zmq.services import PendingCall, RouterSockets, ServiceRouter
from ros_gz_bridge_py.transport.zmq.udp import DiscoverySocket, determine_host
from ros_gz_bridge_py.transport.zmq.wire import (
    DATA_FRAMES,
    Frame,
    MessagePublisher,
    PublisherRecord,
    ServicePublisher,
    decode_data,
)

_LOG = logging.getLogger("ros_gz_bridge_py.transport")
T = TypeVar("T")

#: Poll timeout while a retry is pending, and the longest poll otherwise (§2.5: 250 ms).
RETRY_POLL = 0.005
MAX_POLL = 0.25
#: Messages read from one socket per loop turn, so no socket starves the others.
READ_BATCH = 64
#: Cached routes (topic, sender, type frames -> subscriptions, info); cleared beyond this size.
ROUTE_CACHE_SIZE = 1024
#: Where received data goes: the subscriptions that accept it, and what they are told.
Route = tuple[tuple[ZmqSubscription, ...], MessageInfo]


class ZmqNode(Node):
    """A Gazebo Transport node speaking the ZeroMQ protocol (gz-transport wire version 10)."""

    def __init__(
        self,
        partition: str | None = None,
        namespace: str = "",
        settings: TransportSettings | None = None,
    ) -> None:
        self.settings = settings or TransportSettings.from_env()
        self.partition = self.settings.partition if partition is None else partition
        self.namespace = namespace
        fully_qualified_name(self.partition, namespace, "/check")
        self.process_uuid = str(uuid.uuid4())
        self.node_uuid = str(uuid.uuid4())
        #: The node id of the announcements of our publishers under their other spelling
        #: (gz peers keep one record per node and address, so it must differ).
        self.respelled_node_uuid = str(uuid.uuid4())
        self.host = determine_host(self.settings.ip, self.settings.multicast_ip)
        self._counts: collections.Counter[str] = collections.Counter()
        # Touched by the I/O thread only: the per-message fast path takes no lock.
        self._received = 0
        self._routes: dict[tuple[Frame, Frame, Frame], Route] = {}
        self._count_lock = threading.Lock()
        self._closed = False
        self._commands: collections.deque[Callable[[], None]] = collections.deque()
        # Discovery changes, for wait_for_publishers: a counter and its condition.
        self._changed = threading.Condition()
        self._generation = 0
        self._io_thread: threading.Thread | None = None
        self._stopping = False
        # Read by publishing threads without the I/O thread; replaced, never mutated.
        self._subscriptions: dict[str, tuple[ZmqSubscription, ...]] = {}
        #: Remote subscribers per topic, written on the I/O thread (docs/protocol.md §9).
        self.subscriber_book = SubscriberBook()
        self._spellings_version = -1
        self._sub_lock = threading.Lock()
        # I/O thread only. Like gz, the SUB socket never disconnects from an address: ZMQ
        # reconnects if the publisher comes back there, and disconnecting a pipe with data in
        # flight trips a libzmq assertion (fq.cpp, seen with ign-transport11's `-p`).
        self._sub_connected: set[str] = set()
        self._open_resources()

    # --- start and stop --------------------------------------------------------------------

    def _open_resources(self) -> None:
        self._udp: list[DiscoverySocket] = []
        self._context = zmq.Context(io_threads=1)
        self._pub_lock = threading.Lock()
        self._wake_r, self._wake_w = socket.socketpair()
        try:
            self._msg_udp = self._add_udp(self.settings.msg_port)
            self._srv_udp = self._add_udp(self.settings.srv_port)
            self.host = self._msg_udp.interface_ip
            self._pub = self._bound(zmq.PUB, sndhwm=self.settings.sndhwm)
            self._sub = self._socket(zmq.SUB, rcvhwm=self.settings.rcvhwm)
            self.replier_id = str(uuid.uuid4())
            self._replier = self._bound(zmq.ROUTER, routing_id=self.replier_id, mandatory=True)
            self._requester = self._socket(zmq.ROUTER, mandatory=True)
            self.response_id = str(uuid.uuid4())
            self._responses = self._bound(zmq.ROUTER, routing_id=self.response_id)
        except (OSError, zmq.ZMQError) as error:
            self._release()
            msg = f"cannot open the Gazebo Transport sockets on {self.host}: {error}"
            raise TransportError(msg) from error
        self.pub_address: str = self._pub.getsockopt_string(zmq.LAST_ENDPOINT)
        self.replier_address: str = self._replier.getsockopt_string(zmq.LAST_ENDPOINT)
        self.response_address: str = self._responses.getsockopt_string(zmq.LAST_ENDPOINT)
        now = time.monotonic()
        engine_args: dict[str, Any] = {
            "local_ips": {self.host},
            "relays": self.settings.relays,
            "legacy_spelling": self.settings.legacy_spelling,
        }
        self._msg = DiscoveryEngine(self.process_uuid, now, **engine_args)
        self._srv = DiscoveryEngine(self.process_uuid, now, **engine_args)
        sockets = RouterSockets(
            self._srv, lambda out: self._send(self._srv_udp, out), self._requester,
            self._replier, self.response_address, self.response_id, self.node_uuid,
        )  # fmt: skip
        self._services = ServiceRouter(sockets, self.count)
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._io_thread = threading.Thread(target=self._io_main, name="gz-io", daemon=True)
        self._io_thread.start()

    def _add_udp(self, port: int) -> DiscoverySocket:
        udp = DiscoverySocket(self.settings.multicast_ip, port, self.host)
        self._udp.append(udp)
        return udp

    def _socket(
        self, kind: int, *, rcvhwm: int = 0, routing_id: str = "", mandatory: bool = False
    ) -> Any:
        sock = self._context.socket(kind)
        sock.setsockopt(zmq.LINGER, 0)
        if rcvhwm:
            sock.setsockopt(zmq.RCVHWM, rcvhwm)
        if routing_id:
            sock.setsockopt(zmq.ROUTING_ID, routing_id.encode())
        if mandatory:
            sock.setsockopt(zmq.ROUTER_MANDATORY, 1)
        return sock

    def _bound(
        self, kind: int, *, sndhwm: int = 0, routing_id: str = "", mandatory: bool = False
    ) -> Any:
        sock = self._socket(kind, routing_id=routing_id, mandatory=mandatory)
        if sndhwm:
            sock.setsockopt(zmq.SNDHWM, sndhwm)
        sock.bind(f"tcp://{self.host}:*")
        return sock

    def close(self) -> None:
        """UNADVERTISE, END_CONNECTION and BYE, stop the I/O thread, close every socket."""
        if self._closed:
            return
        subscriptions = [sub for subs in self._subscriptions.values() for sub in subs]
        with contextlib.suppress(TransportError):
            self._call(self._say_goodbye)
        self._closed = True
        self._stopping = True
        self._wake()
        if self._io_thread is not None and self._io_thread is not threading.current_thread():
            self._io_thread.join()
        for sub in subscriptions:
            sub.close()
        self._release()

    def _say_goodbye(self) -> None:
        for subs in list(self._subscriptions.values()):
            for sub in subs:
                self._end_subscription(sub)
        for engine, udp in ((self._msg, self._msg_udp), (self._srv, self._srv_udp)):
            self._send(udp, engine.bye())
        self._services.cancel_all()

    def _release(self) -> None:
        with self._pub_lock:
            for udp in self._udp:
                udp.close()
            self._context.destroy(linger=0)
        self._wake_r.close()
        self._wake_w.close()

    # --- commands into the I/O thread -----------------------------------------------------

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_w.send(b"\0")

    def _post(self, command: Callable[[], None]) -> None:
        if self._closed:
            msg = "the Gazebo Transport node is closed"
            raise TransportError(msg)
        self._commands.append(command)
        self._wake()

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

    def count(self, name: str, amount: int = 1) -> None:
        """Add to one of the ``stats`` counters (thread-safe)."""
        with self._count_lock:
            self._counts[name] += amount

    @property
    def stats(self) -> TransportStats:
        """A snapshot of the counters of the node and of both discovery engines."""
        with self._count_lock:
            counts = dict(self._counts)
        readers = [s.reader for subs in self._subscriptions.values() for s in subs if s.reader]
        counts["messages_received"] = self._received + sum(r.received for r in readers)
        engines = (self._msg.counts, self._srv.counts)
        return TransportStats(
            datagrams_received=sum(c["received"] for c in engines),
            datagrams_malformed=sum(c["malformed"] for c in engines),
            datagrams_wrong_version=sum(c["wrong_version"] for c in engines),
            peers_expired=sum(c["peers_expired"] for c in engines),
            unknown_types=sum(c["unknown_type"] for c in engines),
            **counts,
        )

    # --- topics -----------------------------------------------------------------------------

    def _fqn(self, topic: str) -> str:
        return fully_qualified_name(self.partition, self.namespace, topic)

    def advertise(self, topic: str, msg_type: str) -> ZmqPublisher:
        """Advertise ``topic`` under each spelling of ``msg_type``; re-announced every second."""
        fqn = self._fqn(topic)
        names = spellings(msg_type)
        records = tuple(
            PublisherRecord(
                fqn, self.pub_address, self.process_uuid, node, Scope.ALL, MessagePublisher(name)
            )
            for name, node in zip(names, (self.node_uuid, self.respelled_node_uuid), strict=False)
        )
        cache = WireTypeCache(self.subscriber_book, fqn, names)
        publisher = ZmqPublisher(self, topic, msg_type, records, cache)

        def command() -> None:
            for record in records:
                self._send(self._msg_udp, self._msg.advertise(record))

        self._call(command)
        return publisher

    def unadvertise(self, publisher: ZmqPublisher) -> None:
        """Withdraw ``publisher`` (called by its ``close``)."""

        def command() -> None:
            for record in publisher.records:
                self._send(self._msg_udp, self._msg.unadvertise(record))
            self._update_subscribers(publisher.fqn)

        with contextlib.suppress(TransportError):
            self._call(command)

    def publish(
        self,
        publisher: ZmqPublisher,
        payload: bytes | bytearray | memoryview,
        as_type: str | None = None,
    ) -> None:
        """Local delivery, then one message per spelling a remote subscriber needs (§2.8.1
        step 7, docs/protocol.md §9); ``as_type`` limits both to that spelling."""
        fqn, msg_type = publisher.fqn, publisher.msg_type
        if as_type is None or as_type == msg_type:
            local = [
                sub
                for sub in self._subscriptions.get(fqn, ())
                if not sub.ignore_local and sub.accepts(msg_type)
            ]
            if local:
                data = payload if isinstance(payload, bytes) else bytes(payload)
                info = MessageInfo(
                    publisher.topic, msg_type, self.partition, "", intra_process=True
                )
                for sub in local:
                    sub.offer(data, info)
        types = publisher.wire_types()
        if not types:
            return
        send = self._pub.send
        with self._pub_lock:
            if self._closed:
                return
            for wire_type in types:
                if as_type is not None and wire_type != as_type:
                    continue
                topic, sender, _, type_frame = publisher.wire_frames[wire_type]
                try:  # frame by frame: much cheaper than send_multipart for small messages
                    send(topic, zmq.SNDMORE)
                    send(sender, zmq.SNDMORE)
                    send(payload, zmq.SNDMORE, copy=not isinstance(payload, bytes))
                    send(type_frame)
                except zmq.ZMQError as error:
                    self.count("send_failures")
                    _LOG.debug("publish on %s failed: %s", publisher.topic, error)

    def has_connections(self, publisher: ZmqPublisher) -> bool:
        """True if a remote subscriber or a local subscription matches ``publisher``."""
        if publisher.wire_types():
            return True
        return any(
            not sub.ignore_local and sub.accepts(publisher.msg_type)
            for sub in self._subscriptions.get(publisher.fqn, ())
        )

    def new_reader(
        self,
        fqn: str,
        accepts: Callable[[str, str], bool],
        deliver: Callable[[Frame, MessageInfo], None],
        size: int,
        on_start: Callable[[], None] | None,
    ) -> SubscriptionReader:
        """The SUB socket and thread of a queued subscription (see :mod:`~.zmq_reader`)."""
        return SubscriptionReader(
            self._context, fqn=fqn, partition=self.partition, accepts=accepts,
            deliver=deliver, size=size, rcvhwm=self.settings.rcvhwm, count=self.count,
            on_start=on_start,
        )  # fmt: skip

    def _add_subscription(
        self,
        topic: str,
        msg_type: str,
        deliver: Callable[[Frame, MessageInfo], None],
        *,
        ignore_local: bool,
        queue_size: int | None,
        on_delivery_start: Callable[[], None] | None,
    ) -> ZmqSubscription:
        sub = ZmqSubscription(
            self, topic, self._fqn(topic), msg_type, deliver,
            ignore_local=ignore_local, queue_size=queue_size, on_delivery_start=on_delivery_start,
        )  # fmt: skip
        try:
            self._call(lambda: self._start_subscription(sub))
        except TransportError:
            sub.close()
            raise
        return sub

    def _start_subscription(self, sub: ZmqSubscription) -> None:
        """§2.8.1 steps 2 and 4-5 for a new local subscription."""
        fqn = sub.fqn
        with self._sub_lock:
            known = self._subscriptions.get(fqn, ())
            self._subscriptions[fqn] = (*known, sub)
            self._routes.clear()
        if sub.reader is None and not any(s.reader is None for s in known):
            self._sub.setsockopt(zmq.SUBSCRIBE, fqn.encode())
        sub.record = PublisherRecord(
            fqn, self.pub_address, self.process_uuid, self.node_uuid, Scope.ALL,
            MessagePublisher(sub.msg_type, ctrl=""),
        )  # fmt: skip
        self._msg.add_local_subscriber(sub.record)
        self._send(self._msg_udp, self._msg.subscribe(fqn))
        for record in self._msg.remote_publishers(fqn):
            self._connect_publisher(record, [sub])

    def unsubscribe(self, sub: ZmqSubscription) -> None:
        """Remove ``sub`` (called by its ``close``); END_CONNECTION if it was the last."""
        with contextlib.suppress(TransportError):
            self._call(lambda: self._end_subscription(sub))

    def _end_subscription(self, sub: ZmqSubscription) -> None:
        fqn = sub.fqn
        with self._sub_lock:
            remaining = tuple(s for s in self._subscriptions.get(fqn, ()) if s is not sub)
            if remaining:
                self._subscriptions[fqn] = remaining
            else:
                self._subscriptions.pop(fqn, None)
            self._routes.clear()
        if sub.record is not None:
            self._msg.remove_local_subscriber(sub.record)
        if sub.reader is None and not any(s.reader is None for s in remaining):
            self._sub.setsockopt(zmq.UNSUBSCRIBE, fqn.encode())
        if remaining:
            return
        processes = [r.process_uuid for r in self._msg.remote_publishers(fqn)]
        self._send(
            self._msg_udp, self._msg.disconnect(fqn, self.node_uuid, self.pub_address, processes)
        )

    def _connect_publisher(self, record: PublisherRecord, subs: Sequence[ZmqSubscription]) -> None:
        """§2.8.1 step 4-5: connect the SUB once per address, NEW_CONNECTION if a type matches.

        Queued subscriptions read their own SUB socket, which their reader connects."""
        for sub in subs:
            if sub.reader is not None:
                sub.reader.connect(record.address)
        if any(sub.reader is None for sub in subs) and record.address not in self._sub_connected:
            try:
                self._sub.connect(record.address)
            except zmq.ZMQError as error:
                self.count("frames_malformed")
                _LOG.debug("cannot connect to publisher %r: %s", record.address, error)
                return
            self._sub_connected.add(record.address)
        taking = [sub for sub in subs if sub.take(record)]  # every one records what it takes
        if taking:
            self._send(self._msg_udp, self._msg.connect(record, self.node_uuid))

    # --- services ---------------------------------------------------------------------------

    def advertise_service(
        self, service: str, request_type: str, response_type: str, handler: ServiceHandler
    ) -> ZmqServiceOffer:
        """Provide ``service`` for exactly these type strings (§2.9.1)."""
        record = PublisherRecord(
            self._fqn(service), self.replier_address, self.process_uuid, self.node_uuid,
            Scope.ALL, srv=ServicePublisher(self.replier_id, request_type, response_type),
        )  # fmt: skip
        offer = ZmqServiceOffer(self, record, handler, (record.topic, request_type, response_type))
        self._call(lambda: self._services.add_offer(offer))
        return offer

    def unadvertise_service(self, offer: ZmqServiceOffer) -> None:
        """Withdraw ``offer`` (called by its ``close``)."""
        with contextlib.suppress(TransportError):
            self._call(lambda: self._services.remove_offer(offer))

    def _on_node_thread(self) -> bool:
        return threading.current_thread() is self._io_thread

    def request_async(  # noqa: PLR0917 - positional order fixed by the API contract
        self,
        service: str,
        request: bytes,
        request_type: str,
        response_type: str,
        timeout: float,
        callback: ReplyCallback,
    ) -> None:
        """Call ``service``; ``callback`` runs exactly once on the I/O thread."""
        call = PendingCall(
            self._fqn(service), bytes(request), request_type, response_type,
            time.monotonic() + timeout, callback,
        )  # fmt: skip
        self._post(lambda: self._services.start_call(call))

    # --- listings ---------------------------------------------------------------------------

    def _wait_for_init(self) -> None:
        remaining = self._msg.started + INIT_DELAY - time.monotonic()
        if remaining > 0:
            time.sleep(remaining)

    def _names(self, engine: DiscoveryEngine, services: bool) -> list[str]:
        names: set[str] = set()
        for record in engine.all_publishers():
            parts = decompose(record.topic)
            if parts is None or (record.srv is not None) != services:
                continue
            partition, name = parts
            if partition.removeprefix("/") == self.partition:
                names.add(name)
        return sorted(names)

    def _infos(self, engine: DiscoveryEngine, topic: str) -> list[TopicInfo]:
        fqn = self._fqn(topic)
        name = (decompose(fqn) or ("", topic))[1]
        infos = []
        for record in engine.all_publishers():
            if record.topic != fqn:
                continue
            req = rep = ""
            msg_type = record.msg_type
            if record.srv is not None:
                req, rep = record.srv.request_type, record.srv.response_type
                msg_type = f"{req}&{rep}"
            ids = (record.address, record.process_uuid, record.node_uuid)
            infos.append(TopicInfo(name, msg_type, *ids, request_type=req, response_type=rep))
        return infos

    def topic_list(self) -> list[str]:
        """Topics with a publisher in this partition (waits until discovery is initialised)."""
        self._wait_for_init()
        return self._call(lambda: self._names(self._msg, services=False))

    def topic_info(self, topic: str) -> list[TopicInfo]:
        """Publishers of ``topic`` (waits until discovery is initialised)."""
        self._wait_for_init()
        return self._call(lambda: self._infos(self._msg, topic))

    def service_list(self) -> list[str]:
        """Services with a provider in this partition (waits until discovery is initialised)."""
        self._wait_for_init()
        return self._call(lambda: self._names(self._srv, services=True))

    def service_info(self, service: str) -> list[TopicInfo]:
        """Providers of ``service``; ``msg_type`` is ``"<request type>&<response type>"``."""
        self._wait_for_init()
        return self._call(lambda: self._infos(self._srv, service))

    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Publishers (ADVERTISE) and subscribers (SUBSCRIBE, SUBSCRIBERS_REP, NEW_CONNECTION
        to our publishers) of ``topic`` in other processes, in every partition."""
        fqn = self._fqn(topic)
        return self._call(lambda: self._observe(fqn))

    def _observe(self, fqn: str) -> list[GraphEndpoint]:
        own_partition, name = decompose(fqn) or ("", fqn)

        def partition_of(other: str) -> str | None:
            parts = decompose(other)
            return parts[0].removeprefix("/") if parts is not None and parts[1] == name else None

        found = [
            GraphEndpoint(PUBLISHER, partition, name, record.msg_type, record.process_uuid,
                          record.address)
            for record in self._msg.all_publishers()
            if record.msg is not None
            and record.process_uuid != self.process_uuid
            and (partition := partition_of(record.topic)) is not None
        ]  # fmt: skip
        # Per (partition, process), the best we know: SUBSCRIBE (no type), then a listing
        # (its type), then a registration with our publisher (the spellings it took).
        subscribers: dict[tuple[str, str], GraphEndpoint] = {}
        for topic, seen in self._msg.subscribe_sightings().items():
            if (partition := partition_of(topic)) is not None:
                for process, ip in seen.items():
                    subscribers[partition, process] = GraphEndpoint(
                        SUBSCRIBER, partition, name, "", process, ip
                    )
        for record in self._msg.listed_subscribers():
            if (partition := partition_of(record.topic)) is not None:
                subscribers[partition, record.process_uuid] = GraphEndpoint(
                    SUBSCRIBER, partition, name, record.msg_type, record.process_uuid,
                    record.address,
                )  # fmt: skip
        own_partition = own_partition.removeprefix("/")
        for remote in self._msg.remote_subscribers(fqn):
            msg_type = next(iter(remote.types)) if len(remote.types) == 1 else GENERIC_TYPE
            known = subscribers.get((own_partition, remote.process_uuid))
            subscribers[own_partition, remote.process_uuid] = GraphEndpoint(
                SUBSCRIBER, own_partition, name, msg_type, remote.process_uuid,
                known.location if known else "", registered=True,
            )  # fmt: skip
        found += [sub for sub in subscribers.values() if sub.process_uuid != self.process_uuid]
        return found

    def peer_processes(self) -> int:
        """Other processes heard on either discovery port and not yet expired."""
        return self._call(lambda: len({*self._msg.processes(), *self._srv.processes()}))

    def listening(self) -> str:
        """Backend, partition, discovery group and ports, the interface and any relays."""
        relays = f", relays {', '.join(self.settings.relays)}" if self.settings.relays else ""
        return (
            f"ZeroMQ discovery on {self.settings.multicast_ip} ports {self.settings.msg_port} "
            f"(topics) and {self.settings.srv_port} (services) via {self.host}{relays}, "
            f"partition '{self.partition}'"
        )

    def ask_subscribers(self) -> None:
        """SUBSCRIBERS_REQ, if every peer is gz-transport 13+ (11/12 print an error for it)."""

        def command() -> None:
            spellings = self._msg.spellings
            if spellings.modern and not spellings.legacy_processes:
                self._send(self._msg_udp, self._msg.subscribers_request())

        with contextlib.suppress(TransportError):
            self._post(command)

    def wait_for_publishers(
        self, topic: str, timeout: float, msg_type: str | None = None
    ) -> list[TopicInfo]:
        """Publishers of ``topic`` (of ``msg_type`` if given) as soon as one is known."""
        deadline = time.monotonic() + timeout
        while True:
            seen = self._generation
            infos = self._call(lambda: self._infos(self._msg, topic))
            found = [i for i in infos if msg_type is None or i.msg_type == msg_type]
            remaining = deadline - time.monotonic()
            if found or remaining <= 0:
                return found
            self._wait_for_change(seen, remaining)

    def _wait_for_change(self, seen: int, timeout: float) -> None:
        with self._changed:
            self._changed.wait_for(lambda: self._generation != seen, timeout)

    # --- the I/O thread ---------------------------------------------------------------------

    def _send(self, udp: DiscoverySocket, datagrams: list[Outgoing]) -> None:
        for out in datagrams:
            if not udp.send(out.data, out.relay_ip):
                self.count("send_failures")

    def _io_main(self) -> None:
        poller = zmq.Poller()
        poller.register(self._wake_r.fileno(), zmq.POLLIN)
        for udp in self._udp:
            poller.register(udp.fileno(), zmq.POLLIN)
        for sock in (self._sub, self._replier, self._responses):
            poller.register(sock, zmq.POLLIN)
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
        return max(0.0, self._services.next_deadline(deadline) - now)

    def _io_turn(self, ready: dict[Any, int]) -> None:
        if self._wake_r.fileno() in ready:
            with contextlib.suppress(BlockingIOError):
                self._wake_r.recv(4096)
        while self._commands:
            self._commands.popleft()()
        for udp, engine in ((self._msg_udp, self._msg), (self._srv_udp, self._srv)):
            if udp.fileno() in ready:
                self._read_discovery(udp, engine)
        handlers = (
            (self._sub, self._on_data),
            (self._replier, self._services.on_request),
            (self._responses, self._services.on_response),
        )
        for sock, handler in handlers:
            if sock in ready:
                self._read_frames(sock, handler)
        now = time.monotonic()
        for udp, engine in ((self._msg_udp, self._msg), (self._srv_udp, self._srv)):
            out, events = engine.tick(now)
            self._send(udp, out)
            self._handle_events(engine, events)
        self._services.turn(now)

    def _read_discovery(self, udp: DiscoverySocket, engine: DiscoveryEngine) -> None:
        for _ in range(READ_BATCH):
            received = udp.receive()
            if received is None:
                break
            out, events = engine.datagram_received(*received, time.monotonic())
            self._send(udp, out)
            self._handle_events(engine, events)
        spellings = self._msg.spellings
        if spellings.version != self._spellings_version:
            self._spellings_version = spellings.version
            self.subscriber_book.set_spellings(spellings.snapshot())

    def _read_frames(self, sock: Any, handler: Callable[[list[Frame]], None]) -> None:
        for _ in range(READ_BATCH):
            try:
                frames = receive_message(sock)
            except zmq.Again:
                return
            try:
                handler(frames)
            except RemoteProtocolError as error:
                self.count("frames_malformed")
                _LOG.debug("dropped ZMQ message: %s", error)

    def _on_data(self, frames: list[Frame]) -> None:
        """§2.8.1 step 8: exact FQN, exact or generic type.

        A (topic, sender, type) seen before takes the cached route: no decoding, no matching.
        The cache is emptied whenever a subscription starts or ends (both on this thread).
        """
        if len(frames) == DATA_FRAMES:
            route = self._routes.get((frames[0], frames[1], frames[3]))
            if route is not None:
                self._received += 1
                subs, info = route
                payload = frames[2]
                for sub in subs:
                    sub.offer(payload, info)
                return
        self._route(frames)

    def _route(self, frames: list[Frame]) -> None:
        message = decode_data(frames)
        # Queued subscriptions read their own sockets: a message for a topic that has only
        # those reached this socket by prefix (ZeroMQ matches prefixes) and is not ours.
        subs = tuple(s for s in self._subscriptions.get(message.topic, ()) if s.reader is None)
        if not subs:
            return
        self._received += 1
        name = (decompose(message.topic) or ("", message.topic))[1]
        info = MessageInfo(
            name, message.msg_type, self.partition, message.sender, intra_process=False
        )
        accepting = tuple(sub for sub in subs if sub.accepts_from(message.sender, message.msg_type))
        key = (frames[0], frames[1], frames[3])
        if all(isinstance(frame, bytes) for frame in key):
            if len(self._routes) >= ROUTE_CACHE_SIZE:
                self._routes.clear()
            self._routes[key] = (accepting, info)
        for sub in accepting:
            sub.offer(message.payload, info)

    def _handle_events(self, engine: DiscoveryEngine, events: list[Event]) -> None:
        if not events:
            return
        for event in events:
            if engine is self._msg:
                self._handle_topic_event(event)
            elif isinstance(event, PublisherAdded):
                self._services.provider_found(event.record.topic)
        with self._changed:
            self._generation += 1
            self._changed.notify_all()

    def _handle_topic_event(self, event: Event) -> None:
        if isinstance(event, PublisherAdded):
            subs = self._subscriptions.get(event.record.topic)
            if subs:
                self._connect_publisher(event.record, subs)
        elif isinstance(event, SubscriberAdded | SubscriberRemoved):
            self._update_subscribers(event.topic)

    def _update_subscribers(self, fqn: str) -> None:
        self.subscriber_book.set_subscribers(fqn, self._msg.remote_subscribers(fqn))
