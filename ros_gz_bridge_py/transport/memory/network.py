"""The network the in-memory nodes of one process meet on: who announces, who registered, who
offers services (:mod:`~.node` says the rules its nodes keep)."""

from __future__ import annotations

import itertools
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ros_gz_bridge_py.msgs.names import Spelling

if TYPE_CHECKING:
    from ros_gz_bridge_py.transport.handles import ServiceOffer
    from ros_gz_bridge_py.transport.memory.node import MemoryGzNode

_NETWORK_IDS = itertools.count(1)


@dataclass(frozen=True)
class Announcement:
    """One publisher under one spelling (an ADVERTISE record)."""

    fqn: str
    msg_type: str
    node: MemoryGzNode
    #: Where its messages come from; one per node, as a ZeroMQ process's PUB address.
    address: str


class MemoryNetwork:
    """Who announces and who registered, shared by the nodes on it (thread-safe)."""

    def __init__(self) -> None:
        self.name = f"memory-{next(_NETWORK_IDS)}"
        self.lock = threading.RLock()
        self.nodes: list[MemoryGzNode] = []
        self.announcements: list[Announcement] = []
        self.offers: list[ServiceOffer] = []

    def spellings(self) -> dict[str, Spelling]:
        """The native spelling of each node that has one, by process."""
        with self.lock:
            return {n.process_uuid: n.native for n in self.nodes if n.native is not None}


#: The network of ``create_gz_node(NodeOptions(implementation="memory"))``.
DEFAULT_NETWORK = MemoryNetwork()
