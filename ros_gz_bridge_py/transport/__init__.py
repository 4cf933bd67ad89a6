"""Gazebo Transport for Python: a node that talks to gz-transport 8-15 and ign-transport 11.

``create_node()`` returns the backend gz itself would use: ``GZ_TRANSPORT_IMPLEMENTATION``
(``zeromq``, the default, or ``zenoh``), or ``NodeOptions.implementation`` when given.
"""

from __future__ import annotations

import dataclasses

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.msgs import GENERIC_TYPE
from ros_gz_bridge_py.transport.api import (
    MessageInfo,
    Node,
    NodeOptions,
    Publisher,
    ServiceOffer,
    Subscription,
    TopicInfo,
    TransportStats,
)
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.node import ZmqNode

__all__ = [
    "GENERIC_TYPE",
    "MessageInfo",
    "Node",
    "NodeOptions",
    "Publisher",
    "ServiceOffer",
    "Subscription",
    "TopicInfo",
    "TransportSettings",
    "TransportStats",
    "ZmqNode",
    "create_node",
]


def create_node(options: NodeOptions | None = None) -> Node:
    """A started node for ``options`` (environment defaults when None).

    Raises:
        TransportError: the implementation is not available or the sockets cannot be opened.
    """
    options = options or NodeOptions()
    settings = TransportSettings.from_env()
    if options.legacy_spelling is not None:
        settings = dataclasses.replace(settings, legacy_spelling=options.legacy_spelling)
    implementation = (options.implementation or settings.implementation).lower()
    if implementation == "zenoh":
        # Imported here so the ZeroMQ path never loads zenoh.
        from ros_gz_bridge_py.transport.zenoh.node import ZenohNode  # noqa: PLC0415

        return ZenohNode(options.partition, options.namespace, settings)
    if implementation != "zeromq":
        msg = (
            f"Gazebo Transport implementation {implementation!r} is not available; "
            "use 'zeromq' or 'zenoh' (GZ_TRANSPORT_IMPLEMENTATION)"
        )
        raise TransportError(msg)
    return ZmqNode(options.partition, options.namespace, settings)
