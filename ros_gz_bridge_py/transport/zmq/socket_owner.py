"""A topic's SUB socket and what belongs to it, used from one thread (docs/threads.md).

A :class:`SocketOwner` holds a queued subscription's own SUB socket, subscribed to its one topic
and connected to that topic's publishers (each topic has its own TCP connections, so a flooded
topic's back-pressure never holds another topic's messages), with its connections
(``connections.py``), the cache of what each (topic, sender, type) frames make of a message
(:meth:`SocketOwner.verdict`) and the receive queue's bound in bytes (:meth:`SocketOwner.grew`).
ZeroMQ sockets are single-threaded, so everything here runs on one thread: the driver's, either
a reader's own (``reader.py`` ``SubscriptionReader``) or the native Gazebo -> ROS loop's
(``reader.py`` ``NativeReader``); connects and disconnects from other threads are posted
(:meth:`SocketOwner.post`) and wake the driver.

A message of the topic that cannot be used (malformed frames, a type the subscription does not
take, over the size limit: ``connections.py``) is told to ``reject``; messages of other topics
that share the topic's name as a prefix (ZeroMQ filters by prefix) are not ours and are
skipped without a word.
"""

from __future__ import annotations

import collections
import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import zmq

from ros_gz_bridge_py.errors import RemoteProtocolError
from ros_gz_bridge_py.transport.api import MessageInfo, Rejection
from ros_gz_bridge_py.transport.budget import TURN_MESSAGES
from ros_gz_bridge_py.transport.delivery import MAX_QUEUED_BYTES
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
#: Cached verdicts per (topic, sender, type) frames; cleared beyond this size.
INFO_CACHE_SIZE = 1024
#: How many times the payload that lowers a socket's receive HWM it is lowered for.
GROWTH_ROOM = 2
#: ``zmq.POLLIN`` as a plain int: ``&`` with the enum runs Python code (enum.Flag.__and__).
_POLLIN = int(zmq.POLLIN)
#: What a message's (topic, sender, type) frames make of it: what the callback is told, a
#: rejection (reason, detail), or None (another topic's).
Verdict = MessageInfo | tuple[Rejection, str] | None


@dataclass(frozen=True)
class Topic:
    """The subscription a socket owner reads for: its topic (``fqn``), the spellings it takes
    (``accepts(sender, type)``, ``takes(type)``), where rejections go, the node's settings and
    counter, and the bound of its receive queue in bytes (``large_messages``: by nature large,
    the HWM starts at the largest message taken)."""

    fqn: str
    partition: str
    accepts: Callable[[str, str], bool]
    takes: Callable[[str], bool]
    reject: Callable[[Rejection, str], None]
    settings: TransportSettings
    count: Callable[..., None]
    max_bytes: int = MAX_QUEUED_BYTES
    large_messages: bool = False


class Verdicts:
    """What a topic's messages are, judged once per (topic, sender, type) frames: what the
    subscription's callback is told, a rejection, or None (another topic's, or the other
    spelling of a type taken)."""

    def __init__(self, topic: Topic) -> None:
        self.fqn = fqn = topic.fqn
        self._partition = topic.partition
        self.name = (decompose(fqn) or ("", fqn))[1]
        self._topic_frame = fqn.encode()
        self._accepts = topic.accepts
        self._takes = topic.takes
        self._count = topic.count
        self._limit = topic.settings.max_message_size
        self._infos: dict[tuple[Frame, Frame, Frame], Verdict] = {}

    def verdict(self, frames: list[Frame]) -> Verdict:
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

    def refused(self, address: str) -> tuple[Rejection, str]:
        """The rejection of a message libzmq refused for its size (connections.py)."""
        return (
            Rejection.OVERSIZE,
            f"a message from {address} was larger than {self._limit} bytes "
            "(GZ_TRANSPORT_MAX_MESSAGE_SIZE), or not in ZeroMQ framing: libzmq dropped the "
            "connection before buffering it; reconnecting",
        )

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
                # the other spelling of a message already taken (docs/protocol-lines.md §9)
                return None
            return (
                Rejection.WRONG_TYPE,
                f"the publisher at {message.sender} sends {message.msg_type}",
            )
        return MessageInfo(
            self.name, message.msg_type, self._partition, message.sender, intra_process=False
        )


class SocketOwner:
    """One topic's SUB socket, its connections, verdicts and receive HWM (see the module
    docstring). ``keep(payload, info)`` takes each accepted message :meth:`read` reads;
    ``wake()`` asks the driver's thread for a turn; ``replaced()``, after the socket was
    replaced (:meth:`grew`), lets the driver read the new one."""

    def __init__(
        self,
        context: Any,
        topic: Topic,
        *,
        keep: Callable[[Frame, MessageInfo], None],
        wake: Callable[[], None],
        replacing: Callable[[], None],
        replaced: Callable[[], None],
        largest: int = 0,
    ) -> None:
        self.fqn = topic.fqn
        self._topic_frame = topic.fqn.encode()
        self._verdicts = Verdicts(topic)
        self.verdict = self._verdicts.verdict
        self._keep = keep
        self._reject = topic.reject
        settings = topic.settings
        self._max_bytes = topic.max_bytes
        self._configured_hwm = settings.rcvhwm
        #: The socket's receive HWM now (for the largest message taken, where messages are
        #: large by nature, or for ``largest``), and the largest payload it holds within
        #: max_bytes.
        self._hwm = settings.rcvhwm
        if topic.large_messages:
            self._hwm = hwm_for_bytes(settings.max_message_size, topic.max_bytes, settings.rcvhwm)
        elif largest:
            self._hwm = hwm_for_bytes(GROWTH_ROOM * largest, topic.max_bytes, settings.rcvhwm)
        self.watch: int | None = self._watch_size()
        self._count = topic.count
        self._wake = wake
        self._replacing, self._replaced = replacing, replaced
        self._posted: collections.deque[Callable[[], object]] = collections.deque()
        self._context = context
        self._settings = settings
        self.sock, self.connections = self._open_socket()

    @property
    def name(self) -> str:
        """The topic's name without its partition."""
        return self._verdicts.name

    # --- from any thread --------------------------------------------------------------------

    def post(self, command: Callable[[], object]) -> None:
        """Run ``command`` on the owner's thread soon."""
        self._posted.append(command)
        self._wake()

    # --- the owner's thread -----------------------------------------------------------------

    def run_posted(self) -> None:
        while self._posted:
            self._posted.popleft()()

    def read(self, budget: int = TURN_MESSAGES) -> None:
        """Reads at most ``budget`` messages, each kept or rejected."""
        sock = self.sock
        for _ in range(budget):
            if self.sock is not sock:  # replaced by grew: read from the new one later
                return
            if not sock.getsockopt(zmq.EVENTS) & _POLLIN:  # cheaper than raising zmq.Again
                return
            frames = receive_message(sock)
            verdict = self.verdict(frames)
            if isinstance(verdict, MessageInfo):
                self._keep(frames[2], verdict)
                if self.watch is not None and len(frames[2]) > self.watch:
                    self.grew(len(frames[2]))  # reads what waits: after this one, in order
            elif verdict is not None:
                self._reject(*verdict)

    def turn_connections(self, now: float, *, monitor: bool) -> None:
        """The connections' share: monitor events (``monitor``: the monitor has some) and
        what is due."""
        if monitor or self.connections.is_due(now):
            self.connections.turn()

    def grew(self, size: int) -> None:
        """A payload of ``size`` bytes would make libzmq's queue in front of ours (RCVHWM
        messages of any size per connection) hold more than ``max_bytes``: the HWM is lowered
        to fit payloads of up to :data:`GROWTH_ROOM` times that size (``hwm.py``; a topic
        whose messages grow by small steps changes socket once per doubling, not at each step)
        on a new socket, connected where the old one was, which replaces it: libzmq applies
        an HWM set on a socket to its open connections too, which then stall for good, or
        crash it while a connection closes (docs/protocol-zmq-data.md §2.8.7, "The receive queue in
        bytes"). What the old socket holds is read first (one batch more); what is still on its way
        in its connections is lost, once per lowering."""
        hwm = hwm_for_bytes(GROWTH_ROOM * size, self._max_bytes, self._configured_hwm)
        if 0 < self._hwm <= hwm:
            return  # as low already (a size the native pump told before the last lowering)
        self._hwm = hwm
        self.watch = self._watch_size()
        sock, connections = self._open_socket()
        for address in self.connections.connected:
            connections.connect(address)
        self._replacing()
        self.read()
        old_sock, old_connections = self.sock, self.connections
        self.sock, self.connections = sock, connections
        old_connections.close()
        old_sock.close(linger=0)
        _LOG.info(
            "%s: a payload of %d bytes: its receive queue now holds %d messages per "
            "publisher (parameter max_queued_bytes, %d bytes); connected anew to %d "
            "publisher(s)",
            self.fqn, size, hwm, self._max_bytes, len(connections.connected),
        )  # fmt: skip
        self._replaced()

    def release(self) -> None:
        """Closes the socket and its connections."""
        self.connections.close()
        self.sock.close(linger=0)

    # --- internals --------------------------------------------------------------------------

    def _watch_size(self) -> int | None:
        return watch_size(self._hwm, self._max_bytes)

    def _open_socket(self) -> tuple[Any, SubConnections]:
        """A SUB socket of the topic with the receive HWM as it is now, and its connections."""
        sock = subscriber_socket(self._context, self._settings, self._hwm)
        sock.setsockopt(zmq.SUBSCRIBE, self._topic_frame)
        connections = SubConnections(
            sock, drain=self.read, on_refused=self._refused, count=self._count, what=self.fqn
        )
        return sock, connections

    def _refused(self, address: str) -> None:
        self._reject(*self._verdicts.refused(address))


def watch_size(hwm: int, max_bytes: int) -> int | None:
    """The largest payload a receive HWM of ``hwm`` messages holds within ``max_bytes``;
    None where the HWM is as low as it goes."""
    if 0 < hwm <= MIN_HWM:
        return None
    return max_bytes // (hwm if hwm > 0 else DEFAULT_HWM)


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
