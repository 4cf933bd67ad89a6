"""Received data messages to the local subscriptions that take them (I/O thread only).

docs/protocol-zmq-data.md §2.8.1 step 8: the exact fully qualified name (ZeroMQ filters by prefix),
and a spelling the subscription takes from that sender (docs/protocol-lines.md §9). A (topic,
sender, type) seen before takes its cached route: no decoding, no matching; the node empties the
cache whenever a subscription starts or ends (on the same thread). Subscriptions of the exact topic
that do not take the message's type, or that get malformed frames, are told (``reject``).
"""

from __future__ import annotations

from collections.abc import Callable

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.transport.api import MessageInfo, Rejection
from ros_gz_bridge_py.transport.handles import Subscription
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.zmq.wire import DATA_FRAMES, Frame, decode_data

#: Cached routes (topic, sender, type frames -> subscriptions, info); cleared beyond this size.
ROUTE_CACHE_SIZE = 1024
#: Where received data goes: the subscriptions that accept it, what they are told, and those
#: of the topic that do not take its type.
Route = tuple[tuple[Subscription, ...], MessageInfo, tuple[Subscription, ...]]


class DataRouter:
    """Routes the messages of the node's shared SUB socket."""

    def __init__(
        self, subscriptions: Callable[[str], tuple[Subscription, ...]], partition: str
    ) -> None:
        self._subscriptions = subscriptions
        self._partition = partition
        self._routes: dict[tuple[Frame, Frame, Frame], Route] = {}
        #: Messages routed to at least one subscription.
        self.received = 0

    def clear(self) -> None:
        """Forget the cached routes (a subscription started or ended)."""
        self._routes.clear()

    def on_data(self, frames: list[Frame]) -> None:
        """Deliver one message of four frames (§2.8.2).

        Raises:
            RemoteProtocolError: the frames are not a data message.
        """
        if len(frames) == DATA_FRAMES:
            route = self._routes.get((frames[0], frames[1], frames[3]))
            if route is not None:
                subs, info, wrong = route
                payload = _shared(frames[2])
                for sub in subs:
                    sub.offer(payload, info)
                self._wrong_type(wrong, info)
                self.received += bool(subs)
                return
        self._route(frames)

    def _route(self, frames: list[Frame]) -> None:
        try:
            message = decode_data(frames)
        except RemoteProtocolError as error:
            ours = self._unqueued(_text_or_empty(frames[0]))
            if not ours:
                raise
            for sub in ours:
                sub.reject(Rejection.MALFORMED, str(error))
            return
        # Queued subscriptions read their own sockets: a message for a topic that has only
        # those reached this socket by prefix (ZeroMQ matches prefixes) and is not ours.
        subs = self._unqueued(message.topic)
        if not subs:
            return
        name = (decompose(message.topic) or ("", message.topic))[1]
        info = MessageInfo(
            name, message.msg_type, self._partition, message.sender, intra_process=False
        )
        accepting = tuple(s for s in subs if s.accepts_from(message.sender, message.msg_type))
        wrong = tuple(s for s in subs if not s.accepts(message.msg_type))
        key = (frames[0], frames[1], frames[3])
        if all(isinstance(frame, bytes) for frame in key):
            if len(self._routes) >= ROUTE_CACHE_SIZE:
                self._routes.clear()
            self._routes[key] = (accepting, info, wrong)
        self.received += bool(accepting)
        payload = _shared(message.payload)
        for sub in accepting:
            sub.offer(payload, info)
        self._wrong_type(wrong, info)

    def _unqueued(self, fqn: str) -> tuple[Subscription, ...]:
        return tuple(s for s in self._subscriptions(fqn) if s.delivery is None)

    @staticmethod
    def _wrong_type(subs: tuple[Subscription, ...], info: MessageInfo) -> None:
        for sub in subs:
            sub.reject(
                Rejection.WRONG_TYPE,
                f"the publisher at {info.publisher_address} sends {info.msg_type}",
            )


def _shared(payload: Frame) -> Frame:
    """A payload that several subscriptions may be handed: read-only, so that none writes
    into the others' (``transport/api.py`` ``Callback``)."""
    if isinstance(payload, (bytearray, memoryview)):
        return memoryview(payload).toreadonly()
    return payload


def _text_or_empty(frame: Frame) -> str:
    try:
        return bytes(frame).decode()
    except UnicodeDecodeError:
        return ""
