"""Zenoh liveliness tokens of gz-transport 15 (docs/protocol-zenoh.md §4.3, §4.4).

Pure functions: build a token for one of our entities, and parse a token seen on
``@gz/**`` back into who declares what. The format follows rmw_zenoh's graph cache::

    @gz/<P>/<process>/<node>/<node>/<KIND>/%/%/%/<T>/<TYPE>/%/%

with ``/`` replaced by ``%`` in the partition and topic. Parsing accepts exactly what
gz-transport's ``TopicUtils::DecomposeLivelinessToken`` accepts, so our graph matches theirs.
Data and service keys need no builder: they are the fully qualified name itself.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass

from ros_gz_bridge_py.errors import LocalProtocolError
from ros_gz_bridge_py.transport.names import decompose, is_valid_partition, is_valid_topic

#: The verbatim first chunk of every gz token.
LIVELINESS_PREFIX = "@gz"
#: What every gz process's liveliness subscriber listens to.
GRAPH_KEY = LIVELINESS_PREFIX + "/**"
#: Separator of the request and response types of a service token.
TYPE_SEPARATOR = "&"
_SLASH_REPLACEMENT = "%"
#: Chunks in a token: prefix, partition, 3 ids, kind, 3 placeholders, topic, type, 2 placeholders.
_CHUNKS = 13


class EntityKind(enum.StrEnum):
    """The entity a token announces."""

    PUBLISHER = "MP"
    SUBSCRIBER = "MS"
    SERVICE = "SS"


def mangle_name(name: str) -> str:
    """``/foo/bar`` → ``%foo%bar``."""
    return name.replace("/", _SLASH_REPLACEMENT)


def demangle_name(name: str) -> str:
    """``%foo%bar`` → ``/foo/bar``."""
    return name.replace(_SLASH_REPLACEMENT, "/")


def mangle_types(types: Sequence[str]) -> str | None:
    """Join type names with ``&``; None if the list is empty or a name is empty or has ``&``."""
    if not types or any(not t or TYPE_SEPARATOR in t for t in types):
        return None
    return TYPE_SEPARATOR.join(types)


def demangle_types(mangled: str) -> list[str] | None:
    """Split ``req&rep`` into its names; None if any name is empty."""
    types = mangled.split(TYPE_SEPARATOR)
    return None if any(not t for t in types) else types


def _token(fqn: str, process_uuid: str, node_uuid: str, kind: EntityKind, type_chunk: str) -> str:
    parts = decompose(fqn)
    if parts is None:
        msg = f"{fqn!r} is not a fully qualified name '@<partition>@<topic>'"
        raise LocalProtocolError(msg)
    partition, topic = parts
    if not partition:
        msg = (
            f"{fqn!r} has an empty partition, which gives no valid Zenoh liveliness token; "
            "set GZ_PARTITION (or the node's partition) to a non-empty name"
        )
        raise LocalProtocolError(msg)
    if "/" in type_chunk:
        msg = f"type name {type_chunk!r} contains '/', which would corrupt the liveliness token"
        raise LocalProtocolError(msg)
    chunks = (
        LIVELINESS_PREFIX, mangle_name(partition), process_uuid, node_uuid, node_uuid, kind.value,
        "%", "%", "%", mangle_name(topic), type_chunk, "%", "%",
    )  # fmt: skip
    return "/".join(chunks)


def message_token(
    fqn: str, process_uuid: str, node_uuid: str, kind: EntityKind, msg_type: str
) -> str:
    """The MP or MS token of a publisher or subscription on topic ``fqn``.

    Raises:
        LocalProtocolError: ``fqn`` is malformed or has an empty partition.
    """
    return _token(fqn, process_uuid, node_uuid, kind, msg_type)


def service_token(
    fqn: str, process_uuid: str, node_uuid: str, request_type: str, response_type: str
) -> str:
    """The SS token of a service provider.

    Raises:
        LocalProtocolError: ``fqn`` is malformed, or a type name is empty or contains ``&``.
    """
    mangled = mangle_types((request_type, response_type))
    if mangled is None:
        msg = (
            f"service types {request_type!r} and {response_type!r} must be non-empty "
            f"and must not contain {TYPE_SEPARATOR!r}"
        )
        raise LocalProtocolError(msg)
    return _token(fqn, process_uuid, node_uuid, EntityKind.SERVICE, mangled)


@dataclass(frozen=True, slots=True)
class GraphToken:
    """What one liveliness token says.

    ``msg_type`` is the type chunk as written (``req&rep`` for services), and for services
    ``request_type``/``response_type`` hold the two halves.
    """

    partition: str
    topic: str
    process_uuid: str
    node_uuid: str
    #: ``MP``, ``MS`` or ``SS``; gz ignores other kinds, and so do we.
    kind: str
    msg_type: str
    request_type: str = ""
    response_type: str = ""

    @property
    def fqn(self) -> str:
        """The fully qualified name, rebuilt as gz does: ``@<partition>@<topic>``."""
        return f"@{self.partition}@{self.topic}"


def parse_token(token: str) -> GraphToken | None:
    """Decompose ``token``; None if gz-transport would reject it.

    The rules are those of gz-transport 15's DecomposeLivelinessTokenHelper: it starts with
    ``@``, has exactly 13 ``/``-separated chunks, chunks 1 to 9 are non-empty, the demangled
    partition and topic are valid names and the type-hash chunk is non-empty. A service
    token (``SS``) must carry exactly two non-empty types.
    """
    chunks = token.split("/")
    if not token.startswith("@") or len(chunks) != _CHUNKS:
        return None
    if not all(chunks[1:10]) or not chunks[11]:
        return None
    partition, topic = demangle_name(chunks[1]), demangle_name(chunks[9])
    if not is_valid_partition(partition) or not is_valid_topic(topic):
        return None
    kind, type_chunk = chunks[5], chunks[10]
    request_type = response_type = ""
    if kind == EntityKind.SERVICE:
        types = demangle_types(type_chunk)
        if types is None or len(types) != 2:
            return None
        request_type, response_type = types
    return GraphToken(
        partition, topic, chunks[2], chunks[3], kind, type_chunk, request_type, response_type
    )
