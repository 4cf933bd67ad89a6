"""The values every Gazebo Transport backend speaks in: options, message infos, listings,
graph endpoints, counters and callback types. The node contract itself is
:class:`~ros_gz_bridge_py.transport.node.GzNode`; payloads are serialized protobuf bytes.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, Protocol

from ros_gz_bridge_py.msgs.names import Spelling


class Rejection(enum.StrEnum):
    """Why a message that reached a subscription could not be used (the channel counts each)."""

    #: The payload is not a valid message of its type.
    UNDECODABLE = "undecodable payload"
    #: The frames are not a Gazebo Transport data message (count, or names that are not text).
    MALFORMED = "malformed frame"
    #: A message of a type the subscription does not take.
    WRONG_TYPE = "wrong type"
    #: Larger than the maximum message size (``GZ_TRANSPORT_MAX_MESSAGE_SIZE``).
    OVERSIZE = "over the size limit"
    #: Sizes in the message that do not describe its data (images, point clouds).
    INCONSISTENT_SIZES = "inconsistent sizes"
    #: Any other content the converter refuses.
    CONVERSION = "conversion error"


class Scope(enum.IntEnum):
    """How far an advertisement travels (Discovery.Publisher.Scope, docs/protocol-zmq-discovery.md
    §2.6)."""

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
    ``planned_subscriptions``: how many Gazebo topics the caller will subscribe at its start;
    where GZ_TRANSPORT_RCVHWM is unset, each one's receive queue is smaller the more there are
    (``settings.planned_rcvhwm``).
    ``stop_requested``: asked every 0.1 s while the node starts, which can wait (a Zenoh client
    for its router); True gives the start up (``node_start.py``). None: started in the caller.
    """

    partition: str | None = None
    namespace: str = ""
    implementation: str | None = None
    legacy_spelling: Spelling | None = None
    planned_subscriptions: int = 0
    stop_requested: Callable[[], bool] | None = None


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
    #: Messages of a type no subscription of their topic takes.
    messages_wrong_type: int = 0
    #: Messages refused for their size (ZeroMQ: connections dropped by libzmq for one).
    messages_oversize: int = 0
    #: Publisher addresses from the network that are not ``tcp://host:port``.
    addresses_refused: int = 0
    #: Connections to publishers closed because every record at their address went away.
    publishers_disconnected: int = 0
    #: Handshakes that failed on credentials (GZ_TRANSPORT_USERNAME/PASSWORD), both ways.
    auth_failures: int = 0
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


#: Subscription callback: ``callback(payload or message, info)``. A payload handed as a
#: writable buffer is the callback's alone, to keep or write into (the bulk path builds its
#: CDR there, ``bulk/path.py``); one that other subscriptions also get is read-only.
Callback = Callable[[Any, MessageInfo], None]
#: Told about each message a subscription could not use: ``on_reject(reason, detail)``.
RejectCallback = Callable[[Rejection, str], None]


class NativeHost(Protocol):
    """The reader a :class:`NativeLoop` reads for (``zmq/reader.py`` ``NativeReader``): its
    socket owner's share of the work, on the loop's thread."""

    def native_turn(
        self, unrouted: list[list[Any]], *, monitor: bool, broken: bool, grown: int = 0
    ) -> float | None:
        """Judges the frames the loop had no route for, runs posted commands and the
        connections (``monitor``: the connection monitor has events; ``broken``: the socket
        cannot be read any more; ``grown``: the largest payload read above the size
        :meth:`NativeLoop.watch` set, or 0); returns when it wants its next turn at the latest
        (``time.monotonic()``), or None."""
        ...


class NativeSocketReader(Protocol):
    """A socket a :class:`NativeLoop` reads for several subscriptions of one node (their
    topics' small messages through one connection per publisher, docs/native.md §5)."""

    def wake(self) -> None:
        """Calls its host's ``native_turn`` soon (from any thread)."""

    def close(self) -> None:
        """Returns once the loop no longer reads the socket."""


class NativeLoop(Protocol):
    """A per-message loop that reads a subscription's ZeroMQ socket outside Python
    (``native/pump.py``, on the process's one loop thread, ``native/loop.py``); the ZeroMQ
    reader attaches its socket instead of reading it, and judges only what it hands back
    (``zmq/reader.py``). Other backends do not use it."""

    def learn(self, sender: bytes, msg_type: bytes, *, take: bool) -> None:
        """Messages of (sender, type) are the loop's from now on (``take``), or skipped."""

    def attach(self, sock: int, monitor: int, host: NativeHost) -> None:
        """Read ``sock`` (a socket's address, with its connection ``monitor``) from now on;
        ``host.native_turn`` runs on the loop's thread. No route is known at first."""

    def socket_reader(self, sock: int, monitor: int, host: NativeHost) -> NativeSocketReader:
        """A reader of ``sock`` (with its connection ``monitor``) on this loop for several
        subscriptions (:meth:`attach_shared`); ``host.native_turn`` runs on the loop's thread
        for the socket's own share (its connections, posted commands)."""
        ...

    def attach_shared(self, reader: NativeSocketReader, host: NativeHost) -> None:
        """Take this subscription's messages from ``reader``'s socket from now on;
        ``host.native_turn`` runs on the loop's thread. No route is known at first."""

    def detach(self) -> None:
        """Returns once the loop no longer touches the sockets, nor a reader the
        subscription."""

    def wake(self) -> None:
        """Calls ``host.native_turn`` soon (from any thread)."""

    def watch(self, size: int | None) -> None:
        """Payloads larger than ``size`` bytes are told to ``host.native_turn`` (``grown``);
        None: none."""

    @property
    def received(self) -> int:
        """Messages it took from the socket."""
        ...

    @property
    def dropped(self) -> int:
        """Messages it dropped."""
        ...

    @property
    def dropped_sender(self) -> str:
        """The sender of the last message it dropped ("" before any)."""
        ...


#: Service handler: ``handler(request bytes) -> (success, response bytes)``.
ServiceHandler = Callable[[bytes], tuple[bool, bytes]]
#: Async service callback: ``(True/False, reply)`` on a reply, ``(None, b"")`` on timeout.
ReplyCallback = Callable[[bool | None, bytes], None]
#: Response types that make a service call one-way (docs/protocol-zmq-data.md §2.9.3,
#: docs/protocol-zenoh.md §4.6): there is no reply, the call is done once the request is sent.
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
