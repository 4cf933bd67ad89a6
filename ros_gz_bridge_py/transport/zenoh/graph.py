"""The Zenoh graph: the ``@gz/…`` liveliness tokens a node has seen, and what they tell
(docs/protocol-zenoh.md §4.4): listings, remote subscribers per topic, and the publishers and
subscribers of a topic in every partition. Thread-safe; no Zenoh calls here.
"""

from __future__ import annotations

import threading

from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER, GraphEndpoint, TopicInfo
from ros_gz_bridge_py.transport.wire_types import RemoteSubscriber
from ros_gz_bridge_py.transport.zenoh.keys import EntityKind, GraphToken

#: Graph roles of the token kinds that are topics.
_ROLES: dict[str, str] = {EntityKind.PUBLISHER: PUBLISHER, EntityKind.SUBSCRIBER: SUBSCRIBER}


class ZenohGraph:
    """Tokens by key, with the queries a node answers from them."""

    def __init__(self, own_process: str) -> None:
        self._own = own_process
        self._lock = threading.Lock()
        self._tokens: dict[str, GraphToken] = {}

    def update(self, key: str, token: GraphToken, alive: bool) -> None:
        """A token appeared (``alive``) or went away."""
        with self._lock:
            if alive:
                self._tokens[key] = token
            else:
                self._tokens.pop(key, None)

    def tokens(self) -> list[GraphToken]:
        with self._lock:
            return list(self._tokens.values())

    def subscribers(self, fqn: str) -> tuple[RemoteSubscriber, ...]:
        """Other processes' MS tokens on ``fqn``, per node with every type it declared."""
        types: dict[tuple[str, str], set[str]] = {}
        for token in self.tokens():
            if token.kind == EntityKind.SUBSCRIBER and token.fqn == fqn and not self._ours(token):
                types.setdefault((token.process_uuid, token.node_uuid), set()).add(token.msg_type)
        return tuple(RemoteSubscriber(p, n, frozenset(t)) for (p, n), t in types.items())

    def names(self, kind: EntityKind, partition: str) -> list[str]:
        """Topic or service names with a token of ``kind`` in ``partition``."""
        own = partition if partition.startswith("/") else "/" + partition
        return sorted({t.topic for t in self.tokens() if t.kind == kind and t.partition == own})

    def infos(self, kind: EntityKind, fqn: str) -> list[TopicInfo]:
        """The tokens of ``kind`` on ``fqn`` as listing rows (no addresses in Zenoh)."""
        return [
            TopicInfo(t.topic, t.msg_type, "", t.process_uuid, t.node_uuid,
                      request_type=t.request_type, response_type=t.response_type)
            for t in self.tokens()
            if t.kind == kind and t.fqn == fqn
        ]  # fmt: skip

    def observe(self, name: str | None = None) -> list[GraphEndpoint]:
        """Other processes' publishers and subscribers of topic ``name`` (None: of every
        topic), every partition."""
        return [
            GraphEndpoint(_ROLES[t.kind], t.partition.removeprefix("/"), t.topic, t.msg_type,
                          t.process_uuid, "")
            for t in self.tokens()
            if t.kind in _ROLES and name in (None, t.topic) and not self._ours(t)
        ]  # fmt: skip

    def peer_processes(self) -> int:
        """Other processes holding tokens."""
        return len({t.process_uuid for t in self.tokens()} - {self._own})

    def _ours(self, token: GraphToken) -> bool:
        return token.process_uuid == self._own
