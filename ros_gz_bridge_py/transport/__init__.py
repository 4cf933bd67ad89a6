"""Gazebo Transport for Python: a node that talks to gz-transport 8-15 and ign-transport 11.

``create_gz_node()`` returns a node of the backend gz itself would use:
``GZ_TRANSPORT_IMPLEMENTATION`` (``zeromq``, the default, or ``zenoh``), or
``NodeOptions.implementation`` when given; ``memory`` is an in-process backend for tests.
Backends are data (:data:`BACKENDS`): a name and where its node class lives, loaded on use,
so the ZeroMQ path never imports zenoh.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib

from ros_gz_bridge_py.errors import TransportError
from ros_gz_bridge_py.msgs import GENERIC_TYPE
from ros_gz_bridge_py.transport.api import (
    GraphEndpoint,
    MessageInfo,
    NodeOptions,
    Rejection,
    TopicInfo,
    TransportStats,
)
from ros_gz_bridge_py.transport.handles import Publisher, ServiceOffer, Subscription
from ros_gz_bridge_py.transport.node import GzNode
from ros_gz_bridge_py.transport.node_start import start_unless_stopped
from ros_gz_bridge_py.transport.settings import TransportSettings

__all__ = [
    "BACKENDS",
    "GENERIC_TYPE",
    "GraphEndpoint",
    "GzNode",
    "MessageInfo",
    "NodeOptions",
    "Publisher",
    "Rejection",
    "ServiceOffer",
    "Subscription",
    "TopicInfo",
    "TransportSettings",
    "TransportStats",
    "create_gz_node",
]

#: Backend name (``GZ_TRANSPORT_IMPLEMENTATION`` value) -> "module:class" of its node.
BACKENDS: dict[str, str] = {
    "zeromq": "ros_gz_bridge_py.transport.zmq.node:ZmqGzNode",
    "zenoh": "ros_gz_bridge_py.transport.zenoh.node:ZenohGzNode",
    "memory": "ros_gz_bridge_py.transport.memory.node:MemoryGzNode",
}


def backend_class(name: str) -> type[GzNode]:
    """The node class of backend ``name`` (case-insensitive).

    Raises:
        TransportError: no backend of that name.
    """
    where = BACKENDS.get(name.lower())
    if where is None:
        msg = (
            f"Gazebo Transport implementation {name!r} is not available; use one of "
            f"{', '.join(sorted(BACKENDS))} (GZ_TRANSPORT_IMPLEMENTATION)"
        )
        raise TransportError(msg)
    module, _, cls = where.partition(":")
    node_class: type[GzNode] = getattr(importlib.import_module(module), cls)
    return node_class


def create_gz_node(options: NodeOptions | None = None) -> GzNode:
    """A started node for ``options`` (environment defaults when None).

    Raises:
        TransportError: the implementation is not available or cannot start.
    """
    options = options or NodeOptions()
    settings = TransportSettings.from_env(planned_subscriptions=options.planned_subscriptions)
    if options.legacy_spelling is not None:
        settings = dataclasses.replace(settings, legacy_spelling=options.legacy_spelling)
    implementation = options.implementation or settings.implementation
    node_class = backend_class(implementation)
    start = functools.partial(node_class, options.partition, options.namespace, settings)
    if options.stop_requested is None:
        return start()
    return start_unless_stopped(start, options.stop_requested, implementation)
