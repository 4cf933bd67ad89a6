"""Fully qualified topic and service names (docs/protocol.md §1.1).

Every topic and service travels on the wire as ``@<partition>@<name>``. These functions build,
check and split that form exactly as gz-transport does, so listings and subscriptions match
the C++ peers byte for byte.
"""

from __future__ import annotations

from ros_gz_bridge_py.errors import LocalProtocolError

#: Longest partition, namespace, topic or fully qualified name gz-transport accepts.
MAX_NAME_LENGTH = 65535

_FORBIDDEN = ("~", " ", "//", "@", ":=")


def _is_valid_name(name: str) -> bool:
    """The rules shared by partitions, namespaces and topics (§1.1)."""
    return (
        name != "/"
        and len(name) <= MAX_NAME_LENGTH
        and not any(token in name for token in _FORBIDDEN)
    )


def is_valid_partition(partition: str) -> bool:
    """True if ``partition`` may be used (the empty partition is valid)."""
    return _is_valid_name(partition)


def is_valid_namespace(namespace: str) -> bool:
    """True if ``namespace`` may be used (the empty namespace is valid)."""
    return _is_valid_name(namespace)


def is_valid_topic(topic: str) -> bool:
    """True if ``topic`` may be used as a topic or service name (it must not be empty)."""
    return bool(topic) and _is_valid_name(topic)


def fully_qualified_name(partition: str, namespace: str, topic: str) -> str:
    """Build ``@<partition>@<name>`` as gz-transport's TopicUtils::FullyQualifiedName does.

    Raises:
        LocalProtocolError: a part breaks the validity rules of §1.1 or the result is too long.
    """
    for label, value, valid in (
        ("partition", partition, is_valid_partition(partition)),
        ("namespace", namespace, is_valid_namespace(namespace)),
        ("topic", topic, is_valid_topic(topic)),
    ):
        if not valid:
            raise LocalProtocolError(
                f"invalid Gazebo Transport {label} {value!r}: it must not contain '~', ' ', "
                f"'//', '@' or ':=', must not be exactly '/'"
                + (" and must not be empty" if label == "topic" else "")
            )
    if partition and not partition.startswith("/"):
        partition = "/" + partition
    partition = partition.removesuffix("/")
    if not namespace.startswith("/"):
        namespace = "/" + namespace
    if not namespace.endswith("/"):
        namespace += "/"
    topic = topic.removesuffix("/")
    name = topic if topic.startswith("/") else namespace + topic
    fqn = f"@{partition}@{name}"
    if len(fqn) > MAX_NAME_LENGTH:
        msg = (
            f"fully qualified name of {topic!r} is {len(fqn)} characters long; "
            f"the limit is {MAX_NAME_LENGTH}"
        )
        raise LocalProtocolError(msg)
    return fqn


def decompose(fqn: str) -> tuple[str, str] | None:
    """Split ``@<partition>@<name>`` into (partition, name); None if ``fqn`` has not that form.

    The partition keeps its leading ``/`` as on the wire. gz listings strip that one ``/`` and
    compare the rest with the caller's partition string exactly (§1.1).
    """
    last = fqn.rfind("@")
    if not fqn.startswith("@") or last == 0:
        return None
    return fqn[1:last], fqn[last + 1 :]
