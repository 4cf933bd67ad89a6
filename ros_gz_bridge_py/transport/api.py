"""The transport API every backend implements (ZeroMQ now, Zenoh next).

Callers (the bridge, the image fast path, tests) use only these names; ``create_node`` in
the package picks the backend. Payloads are serialized protobuf bytes unless a method says
it decodes.
"""

from __future__ import annotations

import abc
import enum
import threading
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, Self

from ros_gz_bridge_py.errors import TransportError, TransportTimeoutError
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling
from ros_gz_bridge_py.transport.delivery import Deliver, raw_deliverer, typed_deliverer


class Scope(enum.IntEnum):
    """How far an advertisement travels (values as in Discovery.Publisher.Scope, §2.6)."""

    PROCESS = 0
    HOST = 1
    ALL = 2


@dataclass(frozen=True)
class NodeOptions:
    """How to create a node.

    ``partition`` None reads GZ_PARTITION, then IGN_PARTITION, else ``<hostname>:<user>``.
    ``implementation`` None reads GZ_TRANSPORT_IMPLEMENTATION (default ``zeromq``).
    ``legacy_spelling`` None assumes Fortress (``ignition.msgs``) for gz-transport 11/12 peers;
    ``Spelling.GZ`` says they are Garden.
    """

    partition: str | None = None
    namespace: str = ""
    implementation: str | None = None
    legacy_spelling: Spelling | None = None


@dataclass(frozen=True, slots=True)
class MessageInfo:
    """What a subscription callback learns besides the payload."""

    #: Topic name without the partition, e.g. ``/chatter``.
    topic: str
    #: The exact type string of the data frame (``gz.msgs.X`` or ``ignition.msgs.X``).
    msg_type: str
    partition: str
    #: The sender's PUB endpoint ("" for intra-process delivery).
    publisher_address: str
    #: True when published by a publisher of this same Node.
    intra_process: bool


@dataclass(frozen=True, slots=True)
class TopicInfo:
    """One publisher (or service provider) known to discovery, like a `gz topic -i` row.

    For services ``msg_type`` is ``"<request type>&<response type>"`` and the two types are
    also in ``request_type``/``response_type`` (empty for topics).
    """

    topic: str
    msg_type: str
    address: str
    process_uuid: str
    node_uuid: str
    request_type: str = ""
    response_type: str = ""


@dataclass(frozen=True, slots=True)
class GraphEndpoint:
    """A publisher or subscriber of a topic that discovery saw, in any partition.

    What explanations and ``parameter_bridge --check`` tell a user about the Gazebo side.
    """

    #: ``"publisher"`` or ``"subscriber"``.
    role: str
    #: The partition as users write it (no leading ``/``).
    partition: str
    #: The topic name without the partition, e.g. ``/cmd_vel``.
    topic: str
    #: The type name, or ``""`` where the protocol does not tell (the subscribers of
    #: gz-transport 11/12 processes, which announce only the topic).
    msg_type: str
    process_uuid: str
    #: Where the endpoint lives: a ZeroMQ address, a host, or ``""``.
    location: str
    #: A subscriber that registered with one of our publishers of this topic.
    registered: bool = False


PUBLISHER = "publisher"
SUBSCRIBER = "subscriber"


@dataclass
class TransportStats:
    """Counters of a node; every bad input from the network lands in one of them."""

    datagrams_received: int = 0
    datagrams_malformed: int = 0
    datagrams_wrong_version: int = 0
    frames_malformed: int = 0
    payloads_undecodable: int = 0
    unknown_types: int = 0
    peers_expired: int = 0
    messages_received: int = 0
    messages_dropped: int = 0
    callback_errors: int = 0
    requests_unhandled: int = 0
    responses_unmatched: int = 0
    send_failures: int = 0
    io_errors: int = 0

    def as_dict(self) -> dict[str, int]:
        """The counters by name."""
        return asdict(self)


#: Raw subscription callback: ``callback(payload, info)``.
RawCallback = Callable[[Any, MessageInfo], None]
#: Typed subscription callback: ``callback(message, info)``.
TypedCallback = Callable[[Any, MessageInfo], None]
#: Service handler: ``handler(request bytes) -> (success, response bytes)``.
ServiceHandler = Callable[[bytes], tuple[bool, bytes]]
#: Async service callback: ``(True/False, reply)`` on a reply, ``(None, b"")`` on timeout.
ReplyCallback = Callable[[bool | None, bytes], None]
#: Response types that make a service call one-way (ZeroMQ §2.9.3, Zenoh §4.6): there is no
#: reply, the call is done once the request is sent.
ONE_WAY_TYPES = frozenset({"gz.msgs.Empty", "ignition.msgs.Empty"})


@dataclass(eq=False)
class ServiceCall:
    """A service call waiting for a provider or a reply; each backend adds its own state."""

    fqn: str
    request: bytes
    request_type: str
    response_type: str
    deadline: float
    callback: ReplyCallback
    dispatched: bool = False


class Publisher(abc.ABC):
    """An advertised topic, announced under both spellings of its type (docs/protocol.md §9)."""

    topic: str
    msg_type: str
    #: ``msg_type`` and its other spelling (if it has one).
    names: tuple[str, ...]

    @abc.abstractmethod
    def publish(self, msg: Any) -> None:
        """Serialize ``msg`` once and send it to every matching subscriber."""

    @abc.abstractmethod
    def publish_raw(
        self, payload: bytes | bytearray | memoryview, *, as_type: str | None = None
    ) -> None:
        """Send an already-serialized message of this publisher's type, once to each
        subscriber in a spelling it takes; ``as_type`` (one of ``names``) only that spelling."""

    @abc.abstractmethod
    def wire_types(self) -> frozenset[str]:
        """The spellings of ``names`` remote subscribers need now."""

    @abc.abstractmethod
    def has_connections(self) -> bool:
        """True if a remote subscriber or a local subscription would receive a message."""

    @abc.abstractmethod
    def close(self) -> None:
        """Unadvertise; idempotent."""


class Subscription(abc.ABC):
    """One subscription; closing it affects no other."""

    topic: str
    msg_type: str

    @property
    @abc.abstractmethod
    def dropped(self) -> int:
        """Messages dropped by the bounded queue (0 without a queue)."""

    @abc.abstractmethod
    def close(self) -> None:
        """Unsubscribe; idempotent."""


class ServiceOffer(abc.ABC):
    """An advertised service."""

    @abc.abstractmethod
    def close(self) -> None:
        """Unadvertise the service; idempotent."""


class Node(abc.ABC):
    """A Gazebo Transport participant: advertise, subscribe, provide and call services."""

    @property
    @abc.abstractmethod
    def stats(self) -> TransportStats:
        """A snapshot of the node's counters."""

    @abc.abstractmethod
    def advertise(self, topic: str, msg_type: str) -> Publisher:
        """Advertise ``topic`` with the exact type string ``msg_type``."""

    def subscribe(
        self,
        topic: str,
        callback: RawCallback,
        msg_type: str = GENERIC_TYPE,
        *,
        ignore_local: bool = False,
        queue_size: int | None = None,
        copy: bool = True,
        on_delivery_start: Callable[[], None] | None = None,
    ) -> Subscription:
        """Receive raw payloads of ``msg_type`` (exact string; GENERIC_TYPE = any).

        ``queue_size`` None runs ``callback`` on the node's I/O thread; N gives the
        subscription its own delivery thread behind a drop-oldest queue of N messages, which
        first runs ``on_delivery_start`` (e.g. to set its own priority).
        ``copy=False`` hands over the backend's buffer (``bytes`` or a read-only
        ``memoryview``) instead of copying it into ``bytes``.
        """
        if on_delivery_start is not None and queue_size is None:
            msg = "on_delivery_start needs a queue_size: without one there is no delivery thread"
            raise ValueError(msg)
        deliver = raw_deliverer(self.count, callback, copy=copy)
        return self._add_subscription(
            topic,
            msg_type,
            deliver,
            ignore_local=ignore_local,
            queue_size=queue_size,
            on_delivery_start=on_delivery_start,
        )

    def subscribe_typed(
        self,
        topic: str,
        msg_class: type[Any],
        callback: TypedCallback,
        *,
        msg_type: str | None = None,
        ignore_local: bool = False,
        queue_size: int | None = None,
    ) -> Subscription:
        """Like :meth:`subscribe`, decoding with ``msg_class.FromString`` (no payload copy).

        ``msg_type`` defaults to the class's full protobuf name, which is always ``gz.msgs.X``:
        to match a Fortress publisher pass ``msg_type="ignition.msgs.X"``. Undecodable
        payloads are counted in ``stats.payloads_undecodable``.
        """
        deliver = typed_deliverer(self.count, msg_class, callback)
        wanted = msg_type or msg_class.DESCRIPTOR.full_name
        return self._add_subscription(
            topic,
            wanted,
            deliver,
            ignore_local=ignore_local,
            queue_size=queue_size,
            on_delivery_start=None,
        )

    @abc.abstractmethod
    def count(self, name: str, amount: int = 1) -> None:
        """Add to one of the ``stats`` counters (thread-safe)."""

    @abc.abstractmethod
    def _add_subscription(
        self,
        topic: str,
        msg_type: str,
        deliver: Deliver,
        *,
        ignore_local: bool,
        queue_size: int | None,
        on_delivery_start: Callable[[], None] | None,
    ) -> Subscription:
        """Register a subscription that hands each matching payload to ``deliver``."""

    @abc.abstractmethod
    def advertise_service(
        self, service: str, request_type: str, response_type: str, handler: ServiceHandler
    ) -> ServiceOffer:
        """Provide ``service``; ``handler`` runs on the I/O thread, an exception means failure."""

    def request(
        self, service: str, request: bytes, request_type: str, response_type: str, timeout: float
    ) -> tuple[bool, bytes]:
        """Call a service and wait for the reply (one-way calls return (True, b"") once sent).

        Raises:
            TransportTimeoutError: no reply within ``timeout`` seconds.
            TransportError: called from the node's own thread, which would wait for itself.
        """
        if self._on_node_thread():
            msg = "request() would block the node's own thread; use request_async() in callbacks"
            raise TransportError(msg)
        done = threading.Event()
        result: list[tuple[bool | None, bytes]] = []

        def on_reply(ok: bool | None, payload: bytes) -> None:
            result.append((ok, payload))
            done.set()

        self.request_async(service, request, request_type, response_type, timeout, on_reply)
        done.wait()
        ok, payload = result[0]
        if ok is None:
            msg = f"service {service!r} did not answer within {timeout} s"
            raise TransportTimeoutError(msg)
        return ok, payload

    @abc.abstractmethod
    def _on_node_thread(self) -> bool:
        """True when the caller runs on the node's own thread (where blocking is forbidden)."""

    @abc.abstractmethod
    def request_async(  # noqa: PLR0917 - positional order fixed by the API contract
        self,
        service: str,
        request: bytes,
        request_type: str,
        response_type: str,
        timeout: float,
        callback: ReplyCallback,
    ) -> None:
        """Call a service; ``callback`` runs exactly once on the I/O thread."""

    @abc.abstractmethod
    def topic_list(self) -> list[str]:
        """Topics with publishers in this partition, like ``gz topic -l``."""

    @abc.abstractmethod
    def topic_info(self, topic: str) -> list[TopicInfo]:
        """Publishers of ``topic``, like ``gz topic -i -t``."""

    @abc.abstractmethod
    def service_list(self) -> list[str]:
        """Services with providers in this partition, like ``gz service -l``."""

    @abc.abstractmethod
    def service_info(self, service: str) -> list[TopicInfo]:
        """Providers of ``service``."""

    @abc.abstractmethod
    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Every publisher and subscriber of ``topic`` (resolved as our own would be) that
        other processes have, in every partition discovery reaches."""

    @abc.abstractmethod
    def peer_processes(self) -> int:
        """How many other Gazebo Transport processes this node hears."""

    @abc.abstractmethod
    def listening(self) -> str:
        """Where this node looks for peers (backend, partition, addresses), for users."""

    @abc.abstractmethod
    def ask_subscribers(self) -> None:
        """Ask peers to list their subscriptions where the protocol can (ZeroMQ, when every
        peer is gz-transport 13 or later); the answers show in :meth:`observe`."""

    @abc.abstractmethod
    def wait_for_publishers(
        self, topic: str, timeout: float, msg_type: str | None = None
    ) -> list[TopicInfo]:
        """Publishers of ``topic`` (of ``msg_type`` if given) once known; [] on timeout."""

    @abc.abstractmethod
    def close(self) -> None:
        """Say goodbye on the wire, stop the thread, close every socket; idempotent."""

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
