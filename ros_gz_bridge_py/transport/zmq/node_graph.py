"""What a ZeroMQ node's discovery knows: the discovery half of :class:`~.node.ZmqGzNode`.

:class:`ZmqGraphView` answers the listings (topics, services, their publishers and providers,
the graph, the peer processes) from the node's two discovery engines on its I/O thread, with
:mod:`~.graph`, and adds the engines' counters to the node's. The node owns the engines, the
sockets and the thread. Sections cited: docs/protocol-zmq-discovery.md.
"""

from __future__ import annotations

import abc
import contextlib
import time
from collections.abc import Callable
from typing import TypeVar

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.transport.api import GraphEndpoint, TopicInfo
from ros_gz_bridge_py.transport.node import GzNode
from ros_gz_bridge_py.transport.zmq import graph
from ros_gz_bridge_py.transport.zmq.discovery import INIT_DELAY, DiscoveryEngine
from ros_gz_bridge_py.transport.zmq.discovery_events import Outgoing
from ros_gz_bridge_py.transport.zmq.sockets import NodeSockets
from ros_gz_bridge_py.transport.zmq.udp import DiscoverySocket

T = TypeVar("T")

#: Our counters for the discovery engines' counts of bad or foreign datagrams
#: (docs/protocol-zmq-discovery.md §2.3).
_ENGINE_COUNTS = {
    "datagrams_received": "received",
    "datagrams_malformed": "malformed",
    "datagrams_wrong_version": "wrong_version",
    "peers_expired": "peers_expired",
    "unknown_types": "unknown_type",
    "addresses_refused": "addresses_refused",
}


class ZmqGraphView(GzNode):
    """The listings of a ZeroMQ node, from its topic (``_msg``) and service (``_srv``) engines."""

    _msg: DiscoveryEngine
    _srv: DiscoveryEngine
    _io: NodeSockets
    host: str

    @abc.abstractmethod
    def _call(self, function: Callable[[], T]) -> T:
        """Run ``function`` on the I/O thread and return its result."""

    @abc.abstractmethod
    def _post(self, command: Callable[[], None]) -> None:
        """Run ``command`` on the I/O thread, not waiting for it."""

    def _add_stats(self, counts: dict[str, int]) -> dict[str, int]:
        """The discovery engines' counts of bad or foreign datagrams."""
        for ours, theirs in _ENGINE_COUNTS.items():
            counts[ours] = counts.get(ours, 0) + self._msg.counts[theirs] + self._srv.counts[theirs]
        return counts

    def _update_subscribers(self, fqn: str) -> None:
        """The remote subscribers of ``fqn`` as discovery knows them, for the spellings."""
        self.subscriber_book.set_subscribers(fqn, self._msg.remote_subscribers(fqn))

    def _datagrams(self, udp: DiscoverySocket, datagrams: list[Outgoing]) -> None:
        for out in datagrams:
            if not udp.send(out.data, out.relay_ip):
                self.count("send_failures")

    def _discovered(self, read: Callable[[], T]) -> T:
        """``read`` on the I/O thread once discovery is initialised (two heartbeats, §2.5),
        as gz's listings wait."""
        remaining = self._msg.started + INIT_DELAY - time.monotonic()
        if remaining > 0:
            time.sleep(remaining)
        return self._call(read)

    def topic_list(self) -> list[str]:
        """Topics with a publisher in this partition."""
        return self._discovered(lambda: graph.names(self._msg, self.partition, services=False))

    def topic_info(self, topic: str) -> list[TopicInfo]:
        """Publishers of ``topic``."""
        return self._discovered(lambda: graph.infos(self._msg, self.fqn(topic)))

    def service_list(self) -> list[str]:
        """Services with a provider in this partition."""
        return self._discovered(lambda: graph.names(self._srv, self.partition, services=True))

    def service_info(self, service: str) -> list[TopicInfo]:
        """Providers of ``service``."""
        return self._discovered(lambda: graph.infos(self._srv, self.fqn(service)))

    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Publishers and subscribers of ``topic`` in other processes, every partition."""
        return self._call(lambda: graph.observe(self._msg, self.fqn(topic), self.process_uuid))

    def graph(self) -> list[GraphEndpoint]:  # GzNode.graph: observe for every topic
        return self._call(lambda: graph.endpoints(self._msg, self.process_uuid))

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
                self._datagrams(self._io.msg_udp, self._msg.subscribers_request())

        with contextlib.suppress(TransportError):
            self._post(command)
