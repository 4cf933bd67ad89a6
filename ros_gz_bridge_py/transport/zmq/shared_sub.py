"""The SUB socket a node's native channels of small messages share (docs/native.md §5).

A socket per topic costs each message a wake-up of libzmq's I/O thread and of the loop: each
topic has TCP connections of its own, and a TCP read brings one message. Gazebo's subscribers
read every topic of a process through one socket; so do the native Gazebo -> ROS channels whose
messages are small by nature (clock, odometry, IMU, joints, TF: not images, point clouds or
other large messages, which keep a socket of their own so that a flood of them never holds up
another topic). One connection per publisher address then carries all their topics, and the
loop reads several messages per wake-up (benchmarks/reports/socket_sharing.md).

A :class:`SharedSub` is that socket, its connections and the native reader that reads it
(``NativeLoop.socket_reader``), made with the node's first such channel and closed with the
node. Each channel's reader (``reader.py`` ``NativeReader``) adds its topic: its pump becomes a
peer of the socket's reader, then the socket subscribes to the topic. A publisher address is
connected once, while one of the topics there has a publisher (counted per topic: a second
connect to one address would duplicate every message), and left as ``connections.py`` leaves
an address. A message libzmq refuses for its size drops the whole connection: every topic with
a publisher at that address is told. A channel whose payloads outgrow what the shared queue
holds within its byte budget moves to a socket of its own (``NativeReader``).

Socket work runs on the loop's thread: commands from other threads are posted and the reader
woken.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol

import zmq

from ros_gz_bridge_py.transport.api import NativeHost, NativeLoop, NativeSocketReader
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.connections import SubConnections
from ros_gz_bridge_py.transport.zmq.socket_owner import receive_message
from ros_gz_bridge_py.transport.zmq.sockets import subscriber_socket
from ros_gz_bridge_py.transport.zmq.wire import Frame

_LOG = logging.getLogger("ros_gz_bridge_py.transport")


class TopicReader(NativeHost, Protocol):
    """What the socket asks of a topic's reader (``reader.py`` ``NativeReader``)."""

    #: The topic's first frame (its fully qualified name).
    topic_frame: bytes

    def take(self, frames: list[Frame]) -> None:
        """A message of the topic, read by Python (before a disconnect)."""

    def refused(self, address: str) -> None:
        """libzmq refused a message from ``address`` for its size (perhaps another topic's)."""

    def connect(self, address: str) -> None:
        """A publisher of the topic at ``address``, for the reader's own socket (it moved
        to one)."""

    def leave(self, address: str) -> None:
        """No publisher of the topic there any more, for the reader's own socket."""


class SharedSub:
    """One SUB socket for the topics of several native readers (see the module docstring);
    ``native`` is the first channel's loop, on which the socket's reader is made."""

    def __init__(
        self,
        context: Any,
        settings: TransportSettings,
        count: Callable[..., None],
        native: NativeLoop,
    ) -> None:
        self.settings = settings
        self._count = count
        self.sock = subscriber_socket(context, settings, settings.shared_rcvhwm)
        self.connections = SubConnections(
            self.sock,
            drain=self._drain,
            on_refused=self._refused,
            count=count,
            what="the native channels' shared SUB socket",
        )
        self._topics: dict[bytes, TopicReader] = {}  # by topic frame
        #: The topics the socket reads for a channel, claimed from any thread (``claim``).
        self._claimed: set[bytes] = set()
        self._claims = threading.Lock()
        self._users: dict[str, set[TopicReader]] = {}  # by publisher address
        self._posted: collections.deque[Callable[[], object]] = collections.deque()
        self._closed = False
        self.reader: NativeSocketReader = native.socket_reader(
            self.sock.underlying, self.connections.monitor.underlying, self
        )

    # --- from any thread --------------------------------------------------------------------

    def claim(self, topic_frame: bytes) -> bool:
        """Whether the socket may read the topic for a new channel: each topic for one
        channel (its messages go to one pump), so a second channel of a topic (one Gazebo
        topic to two ROS topics or types) reads a socket of its own."""
        with self._claims:
            if topic_frame in self._claimed:
                return False
            self._claimed.add(topic_frame)
            return True

    def add(self, reader: TopicReader, native: NativeLoop) -> None:
        """The socket reads ``reader``'s topic (claimed) from now on, for its channel
        ``native``."""
        try:
            native.attach_shared(self.reader, reader)
        except BaseException:
            self._release(reader)
            raise
        self._post(lambda: self._subscribe(reader))

    def remove(self, reader: TopicReader) -> None:
        """The topic's subscription and its publishers go (its channel already left)."""
        self._release(reader)
        self._post(lambda: self._unsubscribe(reader))

    def connect(self, address: str, reader: TopicReader) -> None:
        """A publisher of ``reader``'s topic at ``address``."""
        self._post(lambda: self._connect(address, reader))

    def leave(self, address: str, reader: TopicReader) -> None:
        """No publisher of ``reader``'s topic is at ``address`` any more."""
        self._post(lambda: self._leave(address, reader))

    def wake(self) -> None:
        self.reader.wake()

    def close(self) -> None:
        """The reader off the loop, then the socket closed. Idempotent."""
        if self._closed:
            return
        self._closed = True
        self.reader.close()
        self.connections.close()
        self.sock.close(linger=0)

    # --- the loop's thread (the reader's host) ----------------------------------------------

    def native_turn(
        self, unrouted: list[list[Frame]], *, monitor: bool, broken: bool, grown: int = 0
    ) -> float | None:
        """Posted commands and the connections (the reader hands no frames back: a topic no
        channel reads any more is nobody's)."""
        del unrouted, grown
        if self._closed:
            return None
        if broken:  # the context went away without closing the node
            self._count("io_errors")
            _LOG.warning("the native channels' shared SUB socket cannot be read any more")
            self._closed = True
            self.reader.close()
            return None
        while self._posted:
            self._posted.popleft()()
        if monitor or self.connections.is_due(time.monotonic()):
            self.connections.turn()
        return self.connections.next_deadline()

    def addresses(self, reader: TopicReader) -> list[str]:
        """The publisher addresses connected for ``reader``'s topic."""
        return [address for address, users in self._users.items() if reader in users]

    # --- internals --------------------------------------------------------------------------

    def _release(self, reader: TopicReader) -> None:
        with self._claims:
            self._claimed.discard(reader.topic_frame)

    def _post(self, command: Callable[[], object]) -> None:
        self._posted.append(command)
        self.wake()

    def _subscribe(self, reader: TopicReader) -> None:
        self._topics[reader.topic_frame] = reader
        self.sock.setsockopt(zmq.SUBSCRIBE, reader.topic_frame)

    def _unsubscribe(self, reader: TopicReader) -> None:
        if self._topics.get(reader.topic_frame) is not reader:
            return
        del self._topics[reader.topic_frame]
        self.sock.setsockopt(zmq.UNSUBSCRIBE, reader.topic_frame)
        for address in self.addresses(reader):
            self._leave(address, reader)

    def _connect(self, address: str, reader: TopicReader) -> None:
        if self._topics.get(reader.topic_frame) is not reader:
            reader.connect(address)  # it moved to a socket of its own meanwhile
            return
        if self.connections.connect(address):
            self._users.setdefault(address, set()).add(reader)

    def _leave(self, address: str, reader: TopicReader) -> None:
        users = self._users.get(address)
        if users is None or reader not in users:
            if self._topics.get(reader.topic_frame) is not reader:
                reader.leave(address)  # it moved to a socket of its own meanwhile
            return
        users.discard(reader)
        if not users:
            del self._users[address]
            self.connections.leave(address)

    def _drain(self) -> None:
        """Reads what waits before an address is disconnected (connections.py), each message
        to its topic's reader."""
        while self.sock.getsockopt(zmq.EVENTS) & zmq.POLLIN:
            frames = receive_message(self.sock)
            reader = self._topics.get(bytes(frames[0]))
            if reader is not None:
                reader.take(frames)

    def _refused(self, address: str) -> None:
        """libzmq dropped the connection to ``address`` for a message over the size limit:
        which topic's is not known, so each topic with a publisher there is told."""
        for reader in self._users.get(address, ()):
            reader.refused(address)
