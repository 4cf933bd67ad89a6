"""What a Gazebo Transport node knows of the others: the graph its discovery learned.

:class:`GraphView` is the discovery half of :class:`~ros_gz_bridge_py.transport.node.GzNode`:
each backend answers the queries from its own discovery (topic and service lists, publishers,
every endpoint of the graph, the peers' Gazebo lines) and calls :meth:`GraphView.graph_changed`
when it learns something; waiting for publishers over those is the same everywhere.
"""

from __future__ import annotations

import abc
import threading
import time

from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.transport.api import GraphEndpoint, TopicInfo
from ros_gz_bridge_py.transport.wire_types import SubscriberBook


class GraphView(abc.ABC):
    """Discovery's answers (mixed into ``GzNode``; the backend implements the queries)."""

    #: Remote subscribers per topic and their lines (written by the backend's discovery).
    subscriber_book: SubscriberBook

    def __init__(self) -> None:
        # Discovery changes, for wait_for_publishers: a counter and its condition.
        self._changed = threading.Condition()
        self._generation = 0

    def graph_changed(self) -> None:
        """Backends call this when discovery learned something (wakes wait_for_publishers)."""
        with self._changed:
            self._generation += 1
            self._changed.notify_all()

    def wait_for_publishers(
        self, topic: str, timeout: float, msg_type: str | None = None
    ) -> list[TopicInfo]:
        """Publishers of ``topic`` (of ``msg_type`` if given) as soon as one is known; [] when
        none is within ``timeout``."""
        deadline = time.monotonic() + timeout
        while True:
            seen = self._generation
            found = [
                i for i in self.topic_info(topic) if msg_type is None or i.msg_type == msg_type
            ]
            remaining = deadline - time.monotonic()
            if found or remaining <= 0:
                return found
            self._wait_for_change(seen, remaining)

    def _wait_for_change(self, seen: int, timeout: float) -> None:
        with self._changed:
            self._changed.wait_for(lambda: self._generation != seen, timeout)

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
        """Providers of ``service``; ``msg_type`` is ``"<request type>&<response type>"``."""

    @abc.abstractmethod
    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Every publisher and subscriber of ``topic`` (resolved as our own would be) that
        other processes have, in every partition discovery reaches."""

    @abc.abstractmethod
    def graph(self) -> list[GraphEndpoint]:
        """Every publisher and subscriber that other processes have, of every topic, in every
        partition discovery reaches: :meth:`observe` for all topics at once (discovered
        bridging reads it; filter by ``partition``). A subscriber whose type its protocol
        does not tell (gz-transport 11/12) has ``msg_type`` ``""``."""

    def peer_spelling(self, process_uuid: str) -> Spelling | None:
        """How peer ``process_uuid``'s Gazebo line spells message types, when discovery tells
        it (docs/protocol-lines.md §9.2)."""
        return self.subscriber_book.spelling(process_uuid)

    @abc.abstractmethod
    def peer_processes(self) -> int:
        """How many other Gazebo Transport processes this node hears."""

    @abc.abstractmethod
    def listening(self) -> str:
        """Where this node looks for peers (backend, partition, addresses), for users."""

    @abc.abstractmethod
    def ask_subscribers(self) -> None:
        """Ask peers to list their subscriptions where the protocol has a way (ZeroMQ with
        gz-transport 13+ peers); the answers show in :meth:`observe`."""
