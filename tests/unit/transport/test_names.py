"""Fully qualified names and validity rules (docs/protocol.md §1.1)."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.errors import LocalProtocolError
from ros_gz_bridge_py.transport.names import (
    MAX_NAME_LENGTH,
    decompose,
    fully_qualified_name,
    is_valid_topic,
)


@pytest.mark.parametrize(
    ("partition", "namespace", "topic", "expected"),
    [
        ("myhost:alice", "", "/world/shapes/clock", "@/myhost:alice@/world/shapes/clock"),
        ("testpart", "", "foo", "@/testpart@/foo"),
        ("", "", "/foo", "@@/foo"),
        ("/p/", "ns", "foo/", "@/p@/ns/foo"),
        ("p", "/ns/", "/abs", "@/p@/abs"),
        ("p", "a/b", "c/d", "@/p@/a/b/c/d"),
    ],
)
def test_fully_qualified_name(partition: str, namespace: str, topic: str, expected: str) -> None:
    assert fully_qualified_name(partition, namespace, topic) == expected


@pytest.mark.parametrize("topic", ["", "/", "a b", "a~b", "a//b", "a@b", "a:=b"])
def test_invalid_topics_are_rejected(topic: str) -> None:
    assert not is_valid_topic(topic)
    with pytest.raises(LocalProtocolError, match="topic"):
        fully_qualified_name("p", "", topic)


def test_invalid_partition_and_too_long_name() -> None:
    with pytest.raises(LocalProtocolError, match="partition"):
        fully_qualified_name("a@b", "", "/x")
    with pytest.raises(LocalProtocolError, match="limit"):
        fully_qualified_name("p", "", "/" + "x" * (MAX_NAME_LENGTH - 3))


def test_decompose() -> None:
    assert decompose("@/p:u@/a/b") == ("/p:u", "/a/b")
    assert decompose("@@/foo") == ("", "/foo")
    assert decompose("/foo") is None
    assert decompose("@/foo") is None
