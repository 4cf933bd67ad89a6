"""An in-memory Gazebo Transport: nodes of one process meet on a :class:`MemoryNetwork`.

For tests of the bridge's core without sockets or second processes, and a third backend
under the one contract. It keeps the rules that matter on the wire (docs/protocol-zmq-data.md
§2.8, docs/protocol-lines.md §9): a publisher is announced under each spelling its node uses; a
subscriber registers with an announcement only if it takes that type (NEW_CONNECTION), and takes one
spelling per publisher; a publisher sends nothing while nobody registered, then each message once
per spelling its subscribers need; service calls reach a provider of either spelling of their
types, after it is known, and time out otherwise.

``native`` makes a node stand for a gz process of one Gazebo line: it announces and takes
only that line's spelling (``Spelling.IGNITION`` for Fortress), as real gz-transport does; its
generic subscribers register with every announcement and drop the other line's names.

Threads: a message to a subscription without a queue is delivered on the publishing thread;
service handlers and ``request_async`` callbacks run on the node's worker thread.
"""

from __future__ import annotations

import collections
import functools
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import cast

from ros_gz_bridge_py.msgs.names import Spelling, respell, same_message
from ros_gz_bridge_py.transport.api import (
    ONE_WAY_TYPES,
    PUBLISHER,
    SUBSCRIBER,
    GraphEndpoint,
    MessageInfo,
    Rejection,
    ServiceCall,
    ServiceHandler,
    TopicInfo,
)
from ros_gz_bridge_py.transport.delivery import Payload
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.memory.network import DEFAULT_NETWORK, Announcement, MemoryNetwork
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.node import GzNode
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.wire_types import RemoteSubscriber


class MemoryPublisher(Publisher):
    """A publisher and its announcements, one per spelling its node uses."""

    announcements: tuple[Announcement, ...] = ()


@dataclass(eq=False)
class _Call(ServiceCall):
    """A call waiting for a provider or for its reply; finished once."""

    caller: MemoryGzNode | None = field(default=None)
    done: bool = False


class MemoryGzNode(GzNode):
    """A node on a :class:`MemoryNetwork` (default: the process-wide one)."""

    call_class = _Call

    def __init__(
        self,
        partition: str | None = None,
        namespace: str = "",
        settings: TransportSettings | None = None,
        *,
        network: MemoryNetwork | None = None,
        native: Spelling | None = None,
    ) -> None:
        super().__init__(partition, namespace, settings)
        self.network = network or DEFAULT_NETWORK
        self.native = native
        self.address = f"memory://{self.process_uuid}"
        # fqn -> (process, node) -> the types it registered with our announcements
        self._registered: dict[str, dict[tuple[str, str], frozenset[str]]] = {}
        self._jobs: collections.deque[Callable[[], None]] = collections.deque()
        self._pending: list[_Call] = []
        self._work = threading.Condition()
        self._stop = False
        self._thread = threading.Thread(target=self._work_main, name="gz-memory", daemon=True)
        self._thread.start()
        with self.network.lock:
            self.network.nodes.append(self)
            nodes = list(self.network.nodes)
        for node in nodes:
            node.subscriber_book.set_spellings(self.network.spellings())

    def names_of(self, msg_type: str) -> tuple[str, ...]:
        """Both spellings, or for a native node only its line's (as gz-transport)."""
        if self.native is None:
            return super().names_of(msg_type)
        return (respell(msg_type, self.native),)

    # --- topics -----------------------------------------------------------------------------

    def _open_publisher(
        self, topic: str, fqn: str, msg_type: str, *, own_socket: bool = False, queue_bytes: int = 0
    ) -> Publisher:
        """``own_socket`` and ``queue_bytes`` change nothing here (ZeroMQ notions)."""
        publisher = MemoryPublisher(self, topic, fqn, msg_type)
        publisher.announcements = tuple(
            Announcement(fqn, name, self, self.address) for name in publisher.names
        )
        with self.network.lock:
            self.network.announcements += publisher.announcements
            others = [n for n in self.network.nodes if n is not self]
        for node in others:
            for announcement in publisher.announcements:
                node._announced(announcement)
        self._changed_everywhere()
        return publisher

    def _close_publisher(self, publisher: Publisher) -> None:
        gone = cast(MemoryPublisher, publisher).announcements
        with self.network.lock:
            self.network.announcements = [a for a in self.network.announcements if a not in gone]
            still = any(
                a.node is self and a.fqn == publisher.fqn for a in self.network.announcements
            )
            if not still:
                self._registered.pop(publisher.fqn, None)
        self._update_book(publisher.fqn)
        self._changed_everywhere()

    def _send(self, publisher: Publisher, wire_type: str, payload: Payload) -> None:
        data = bytes(payload)
        with self.network.lock:
            others = [n for n in self.network.nodes if n is not self]
        for node in others:
            node._receive(publisher.fqn, self.address, wire_type, data)

    def _receive(self, fqn: str, sender: str, msg_type: str, payload: bytes) -> None:
        """A message from another node's publisher (§2.8.1 step 8); subscriptions of the topic
        that do not take its type, or all when it is over the size limit, are told."""
        if self.native is not None and respell(msg_type, self.native) != msg_type:
            return  # a name this line's gz-msgs does not know: dropped, as gz does (§9.1)
        every = self.subscriptions(fqn)
        for sub in every:
            if not sub.accepts(msg_type):
                sub.reject(Rejection.WRONG_TYPE, f"the publisher at {sender} sends {msg_type}")
        subs = [s for s in every if s.accepts_from(sender, msg_type)]
        limit = self.settings.max_message_size
        if len(payload) > limit:
            for sub in subs:
                sub.reject(Rejection.OVERSIZE, f"a message of {len(payload)} bytes, over {limit}")
            return
        if not subs:
            return
        self.count("messages_received")
        name = (decompose(fqn) or ("", fqn))[1]
        info = MessageInfo(name, msg_type, self.partition, sender, intra_process=False)
        for sub in subs:
            sub.offer(payload, info)

    def _open_subscription(self, sub: Subscription) -> None:
        with self.network.lock:
            known = [
                a for a in self.network.announcements if a.fqn == sub.fqn and a.node is not self
            ]
        for announcement in known:
            self._take(announcement, [sub])

    def _announced(self, announcement: Announcement) -> None:
        """Another node announced a publisher: register with it if a subscription takes it."""
        self._take(announcement, self.subscriptions(announcement.fqn))

    def _take(self, announcement: Announcement, subs: Sequence[Subscription]) -> None:
        taking = [s for s in subs if self._takes(s, announcement)]
        if taking:
            announcement.node._register(announcement.fqn, self, announcement.msg_type)

    def _takes(self, sub: Subscription, announcement: Announcement) -> bool:
        """Whether ``sub`` registers with ``announcement``. A generic subscriber of a gz
        process (``native``) registers with every announcement of the topic, both spellings
        of one publisher included (§9.1); the publisher then sends it one message, in the
        spelling of its line (§9.2)."""
        if self.native is not None and sub.generic:
            return True
        return sub.take(announcement.address, announcement.msg_type)

    def _register(self, fqn: str, subscriber: MemoryGzNode, msg_type: str) -> None:
        """NEW_CONNECTION: ``subscriber`` takes our publisher of ``fqn`` as ``msg_type``."""
        key = (subscriber.process_uuid, subscriber.node_uuid)
        with self.network.lock:
            by_node = self._registered.setdefault(fqn, {})
            by_node[key] = by_node.get(key, frozenset()) | {msg_type}
        self._update_book(fqn)

    def _unregister(self, fqn: str, subscriber: MemoryGzNode) -> None:
        """END_CONNECTION from ``subscriber``."""
        with self.network.lock:
            by_node = self._registered.get(fqn, {})
            by_node.pop((subscriber.process_uuid, subscriber.node_uuid), None)
        self._update_book(fqn)

    def _update_book(self, fqn: str) -> None:
        with self.network.lock:
            entries = tuple(
                RemoteSubscriber(process, node, types)
                for (process, node), types in self._registered.get(fqn, {}).items()
            )
        self.subscriber_book.set_subscribers(fqn, entries)

    def _close_subscription(self, sub: Subscription, *, last: bool) -> None:
        if not last:
            return
        with self.network.lock:
            publishers = {a.node for a in self.network.announcements if a.fqn == sub.fqn}
        for node in publishers:
            if node is not self:
                node._unregister(sub.fqn, self)

    # --- services ---------------------------------------------------------------------------

    def _open_offer(
        self, service: str, fqn: str, types: tuple[str, str], handler: ServiceHandler
    ) -> ServiceOffer:
        offer = ServiceOffer(self, service, fqn, types, handler)
        with self.network.lock:
            self.network.offers.append(offer)
            nodes = list(self.network.nodes)
        for node in nodes:
            node._post(node._dispatch_pending)
        self._changed_everywhere()
        return offer

    def _close_offer(self, offer: ServiceOffer) -> None:
        with self.network.lock:
            self.network.offers = [o for o in self.network.offers if o is not offer]
        self._changed_everywhere()

    def _start_call(self, call: _Call) -> None:
        """``call``'s callback runs exactly once on this node's worker thread."""
        call.caller = self

        def start() -> None:
            self._pending.append(call)
            self._dispatch_pending()

        self._post(start)

    def _provider(self, call: _Call) -> ServiceOffer | None:
        with self.network.lock:
            for offer in self.network.offers:
                if (
                    offer.fqn == call.fqn
                    and same_message(offer.request_type, call.request_type)
                    and same_message(offer.response_type, call.response_type)
                ):
                    return offer
        return None

    def _dispatch_pending(self) -> None:
        """Worker thread: send the waiting calls whose provider is known now."""
        for call in [c for c in self._pending if not c.dispatched]:
            offer = self._provider(call)
            if offer is None:
                continue
            call.dispatched = True
            provider = cast(MemoryGzNode, offer.node)
            provider._post(functools.partial(self._serve, provider, offer, call))
            if call.response_type in ONE_WAY_TYPES:
                self._finish(call, True, b"")

    def _serve(self, provider: MemoryGzNode, offer: ServiceOffer, call: _Call) -> None:
        """Provider's worker thread: run the handler, send the reply to the caller's."""
        ok, reply = provider.call_handler(offer, call.request)
        if call.response_type not in ONE_WAY_TYPES:
            self._post(lambda: self._finish(call, ok, reply))

    def _finish(self, call: _Call, ok: bool | None, payload: bytes) -> None:
        """Worker thread: the call's callback, once."""
        if call.done:
            return
        call.done = True
        if call in self._pending:
            self._pending.remove(call)
        self.finish_call(call.callback, ok, payload)

    # --- the worker thread ------------------------------------------------------------------

    def _post(self, job: Callable[[], None]) -> None:
        with self._work:
            if self._stop:
                return
            self._jobs.append(job)
            self._work.notify()

    def _on_node_thread(self) -> bool:
        return threading.current_thread() is self._thread

    def _work_main(self) -> None:
        while True:
            with self._work:
                while not self._jobs and not self._stop:
                    deadlines = [c.deadline for c in self._pending if not c.done]
                    wait = min(deadlines) - time.monotonic() if deadlines else None
                    if wait is not None and wait <= 0:
                        break
                    self._work.wait(wait)
                if self._stop:
                    return
                jobs = list(self._jobs)
                self._jobs.clear()
            for job in jobs:
                job()
            now = time.monotonic()
            for call in [c for c in self._pending if c.deadline <= now]:
                self._finish(call, None, b"")

    # --- what the network shows -------------------------------------------------------------

    def _changed_everywhere(self) -> None:
        with self.network.lock:
            nodes = list(self.network.nodes)
        for node in nodes:
            node.graph_changed()

    def _rows(self, services: bool) -> list[tuple[str, str, str, str, str, str]]:
        """(fqn, type, address, process, req, rep) of every announcement or offer."""
        with self.network.lock:
            if services:
                return [
                    (o.fqn, f"{o.request_type}&{o.response_type}", "",
                     cast(MemoryGzNode, o.node).process_uuid, o.request_type, o.response_type)
                    for o in self.network.offers
                ]  # fmt: skip
            return [
                (a.fqn, a.msg_type, a.address, a.node.process_uuid, "", "")
                for a in self.network.announcements
            ]

    def _names(self, services: bool) -> list[str]:
        found = set()
        for fqn, *_ in self._rows(services):
            partition, name = decompose(fqn) or ("", fqn)
            if partition.removeprefix("/") == self.partition:
                found.add(name)
        return sorted(found)

    def _infos(self, topic: str, services: bool) -> list[TopicInfo]:
        fqn = self.fqn(topic)
        name = (decompose(fqn) or ("", topic))[1]
        return [
            TopicInfo(name, msg_type, address, process, process,
                      request_type=req, response_type=rep)
            for row_fqn, msg_type, address, process, req, rep in self._rows(services)
            if row_fqn == fqn
        ]  # fmt: skip

    def topic_list(self) -> list[str]:
        return self._names(services=False)

    def topic_info(self, topic: str) -> list[TopicInfo]:
        return self._infos(topic, services=False)

    def service_list(self) -> list[str]:
        return self._names(services=True)

    def service_info(self, service: str) -> list[TopicInfo]:
        return self._infos(service, services=True)

    def observe(self, topic: str) -> list[GraphEndpoint]:
        """Every other node's publishers and subscriptions of ``topic``, every partition."""
        return self._endpoints((decompose(self.fqn(topic)) or ("", topic))[1])

    def graph(self) -> list[GraphEndpoint]:
        """Every other node's publishers and subscriptions, every topic and partition."""
        return self._endpoints(None)

    def _endpoints(self, name: str | None) -> list[GraphEndpoint]:
        found = []
        with self.network.lock:
            nodes = [n for n in self.network.nodes if n is not self]
            announcements = list(self.network.announcements)
        for a in announcements:
            partition, a_name = decompose(a.fqn) or ("", a.fqn)
            if name in (None, a_name) and a.node is not self:
                found.append(GraphEndpoint(PUBLISHER, partition.removeprefix("/"), a_name,
                                           a.msg_type, a.node.process_uuid, a.address))  # fmt: skip
        for node in nodes:
            for subs in list(node._subscriptions.values()):
                for sub in subs:
                    partition, s_name = decompose(sub.fqn) or ("", sub.fqn)
                    if name in (None, s_name):
                        registered = self._registered.get(sub.fqn, {})
                        taken = (node.process_uuid, node.node_uuid) in registered
                        found.append(GraphEndpoint(SUBSCRIBER, partition.removeprefix("/"),
                                                   s_name, sub.msg_type, node.process_uuid,
                                                   node.address, registered=taken))  # fmt: skip
        return found

    def ask_subscribers(self) -> None:
        """Nothing to ask: the network shows every subscription with its type."""

    def peer_processes(self) -> int:
        with self.network.lock:
            return len(self.network.nodes) - 1

    def listening(self) -> str:
        return f"the in-memory network {self.network.name}, partition '{self.partition}'"

    # --- life -------------------------------------------------------------------------------

    def _shutdown(self) -> None:
        """Leave the network: withdraw announcements, registrations and offers; pending
        calls end as timeouts."""
        with self._work:
            self._stop = True
            self._work.notify()
        if self._thread is not threading.current_thread():
            self._thread.join()
        for call in list(self._pending):
            self._finish(call, None, b"")
        with self.network.lock:
            self.network.announcements = [
                a for a in self.network.announcements if a.node is not self
            ]
            self.network.offers = [o for o in self.network.offers if o.node is not self]
            self.network.nodes.remove(self)
            others = list(self.network.nodes)
        for fqn in list(self._subscriptions):
            for node in others:
                node._unregister(fqn, self)
        for node in others:
            for fqn in list(node._registered):
                node._update_book(fqn)
            node.graph_changed()

    def _release(self) -> None:
        """Nothing to release: no sockets."""
