"""Liveliness tokens against gz-transport 15's own test vectors (src/TopicUtils_TEST.cc)."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.errors import LocalProtocolError
from ros_gz_bridge_py.transport.names import fully_qualified_name
from ros_gz_bridge_py.transport.zenoh.keys import (
    EntityKind,
    GraphToken,
    demangle_name,
    demangle_types,
    mangle_name,
    mangle_types,
    message_token,
    parse_token,
    service_token,
)

# CreateMsgLivelinessToken / decomposeMsgLivelinessToken in TopicUtils_TEST.cc.
UPSTREAM_MP = (
    "@gz/%hostname:user/processUUID/nodeUUID/nodeUUID/MP/%/%/%/%foo/gz::msgs::StringMsg/%/%"
)
# CreateSrvLivelinessToken.
UPSTREAM_SS = (
    "@gz/%hostname:user/processUUID/nodeUUID/nodeUUID/SS/%/%/%/%foo/"
    "gz::msgs::StringMsg&gz::msgs::Empty/%/%"
)
# decomposeSrvLivelinessToken.
UPSTREAM_SS_DOTS = (
    "@gz/%hostname:user/processUUID/nodeUUID/nodeUUID/SS/%/%/%/%foo/"
    "gz.msgs.StringMsg&gz.msgs.Int32/%/%"
)


def test_message_token_matches_upstream() -> None:
    token = message_token(
        "@/hostname:user@/foo", "processUUID", "nodeUUID", EntityKind.PUBLISHER,
        "gz::msgs::StringMsg",
    )  # fmt: skip
    assert token == UPSTREAM_MP


def test_service_token_matches_upstream() -> None:
    token = service_token(
        "@/hostname:user@/foo", "processUUID", "nodeUUID", "gz::msgs::StringMsg",
        "gz::msgs::Empty",
    )  # fmt: skip
    assert token == UPSTREAM_SS


def test_spec_example_and_subscription_token() -> None:
    fqn = fully_qualified_name("myhost:alice", "", "foo")
    pu, nu = "6f1c", "93ab"
    assert message_token(fqn, pu, nu, EntityKind.PUBLISHER, "gz.msgs.StringMsg") == (
        "@gz/%myhost:alice/6f1c/93ab/93ab/MP/%/%/%/%foo/gz.msgs.StringMsg/%/%"
    )
    clock = fully_qualified_name("myhost:alice", "", "/world/shapes/clock")
    assert message_token(clock, pu, nu, EntityKind.SUBSCRIBER, "google.protobuf.Message") == (
        "@gz/%myhost:alice/6f1c/93ab/93ab/MS/%/%/%/%world%shapes%clock/google.protobuf.Message/%/%"
    )


def test_parse_upstream_message_token() -> None:
    assert parse_token(UPSTREAM_MP) == GraphToken(
        "/hostname:user", "/foo", "processUUID", "nodeUUID", "MP", "gz::msgs::StringMsg"
    )
    assert parse_token(UPSTREAM_MP).fqn == "@/hostname:user@/foo"  # type: ignore[union-attr]


def test_parse_upstream_service_token() -> None:
    token = parse_token(UPSTREAM_SS_DOTS)
    assert token is not None
    assert (token.kind, token.topic, token.partition) == ("SS", "/foo", "/hostname:user")
    assert (token.request_type, token.response_type) == ("gz.msgs.StringMsg", "gz.msgs.Int32")
    assert token.msg_type == "gz.msgs.StringMsg&gz.msgs.Int32"


@pytest.mark.parametrize("kind", list(EntityKind))
def test_round_trip(kind: EntityKind) -> None:
    fqn = fully_qualified_name("host:me", "ns", "a/b/c")
    if kind is EntityKind.SERVICE:
        key = service_token(fqn, "p", "n", "gz.msgs.Int32", "gz.msgs.Empty")
    else:
        key = message_token(fqn, "p", "n", kind, "gz.msgs.Int32")
    token = parse_token(key)
    assert token is not None
    assert (token.fqn, token.process_uuid, token.node_uuid, token.kind) == (fqn, "p", "n", kind)


def test_mangling_matches_upstream() -> None:
    assert mangle_name("/foo/bar") == "%foo%bar"
    assert demangle_name("%foo%bar") == "/foo/bar"
    assert mangle_types(["gz::msgs::StringMsg", "gz::msgs::Empty"]) == (
        "gz::msgs::StringMsg&gz::msgs::Empty"
    )
    assert mangle_types(["gz::msgs::StringMsg"]) == "gz::msgs::StringMsg"
    for bad in ([""], [], ["gz::msgs::StringMsg&"], ["&gz::msgs::StringMsg"], ["&"]):
        assert mangle_types(bad) is None
    assert demangle_types("gz::msgs::StringMsg&gz::msgs::Empty") == [
        "gz::msgs::StringMsg",
        "gz::msgs::Empty",
    ]
    for bad_mangled in ("", "gz::msgs::StringMsg&", "&gz::msgs::StringMsg", "&"):
        assert demangle_types(bad_mangled) is None


@pytest.mark.parametrize(
    "key",
    [
        "",
        "gz/%p/pu/nu/nu/MP/%/%/%/%foo/T/%/%",  # no leading @
        "@gz/%p/pu/nu/nu/MP/%/%/%/%foo/T/%",  # too few chunks
        "@gz/%p/pu/nu/nu/MP/%/%/%/%foo/T/%/%/%",  # too many
        "@gz//pu/nu/nu/MP/%/%/%/%foo/T/%/%",  # empty partition
        "@gz/%p//nu/nu/MP/%/%/%/%foo/T/%/%",  # empty process uuid
        "@gz/%p/pu/nu/nu//%/%/%/%foo/T/%/%",  # empty kind
        "@gz/%p/pu/nu/nu/MP/%/%/%//T/%/%",  # empty topic
        "@gz/%p/pu/nu/nu/MP/%/%/%/%foo/T//%",  # empty type hash
        "@gz/%/pu/nu/nu/MP/%/%/%/%foo/T/%/%",  # partition "/"
        "@gz/%p/pu/nu/nu/MP/%/%/%/%/T/%/%",  # topic "/"
        "@gz/%p~x/pu/nu/nu/MP/%/%/%/%foo/T/%/%",  # invalid partition
        "@gz/%p/pu/nu/nu/MP/%/%/%/%%foo/T/%/%",  # topic "//foo"
        "@gz/%p/pu/nu/nu/SS/%/%/%/%foo/gz.msgs.Int32/%/%",  # one service type
        "@gz/%p/pu/nu/nu/SS/%/%/%/%foo/a&b&c/%/%",  # three service types
        "@gz/%p/pu/nu/nu/SS/%/%/%/%foo/a&/%/%",  # empty response type
    ],
)
def test_invalid_tokens_are_rejected(key: str) -> None:
    assert parse_token(key) is None


def test_empty_message_type_is_accepted_like_gz() -> None:
    token = parse_token("@gz/%p/pu/nu/nu/MS/%/%/%/%foo//%/%")
    assert token is not None
    assert token.msg_type == ""


def test_builders_reject_what_gives_no_valid_token() -> None:
    with pytest.raises(LocalProtocolError, match="empty partition"):
        message_token("@@/foo", "p", "n", EntityKind.PUBLISHER, "gz.msgs.Int32")
    with pytest.raises(LocalProtocolError, match="not a fully qualified name"):
        message_token("/foo", "p", "n", EntityKind.PUBLISHER, "gz.msgs.Int32")
    with pytest.raises(LocalProtocolError, match="contains '/'"):
        message_token("@/p@/foo", "p", "n", EntityKind.PUBLISHER, "a/b")
    with pytest.raises(LocalProtocolError, match="must not contain"):
        service_token("@/p@/foo", "p", "n", "a&b", "gz.msgs.Empty")
