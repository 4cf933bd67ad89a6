"""Environment settings with GZ_/IGN_ fallbacks (docs/protocol.md §1.2, §1.4)."""

from __future__ import annotations

import logging
import socket

import pytest

from ros_gz_bridge_py.transport.settings import (
    DEFAULT_MAX_MESSAGE_SIZE,
    TransportSettings,
    default_partition,
    planned_rcvhwm,
)


def test_defaults_without_environment() -> None:
    settings = TransportSettings.from_env({"USER": "alice"})
    assert settings.partition == f"{socket.gethostname()}:alice"
    assert (settings.msg_port, settings.srv_port) == (10317, 10318)
    assert settings.multicast_ip == "239.255.0.7"
    assert settings.ip is None
    assert settings.relays == ()
    assert (settings.rcvhwm, settings.sndhwm) == (1000, 1000)
    assert settings.implementation == "zeromq"


def test_gz_names_win_over_ign_names() -> None:
    env = {
        "GZ_PARTITION": "gz",
        "IGN_PARTITION": "ign",
        "IGN_IP": "127.0.0.2",
        "IGN_RELAY": "1.2.3.4:5.6.7.8",
    }
    settings = TransportSettings.from_env(env)
    assert settings.partition == "gz"
    assert settings.ip == "127.0.0.2"
    assert settings.relays == ("1.2.3.4", "5.6.7.8")


def test_empty_partition_is_kept() -> None:
    assert TransportSettings.from_env({"IGN_PARTITION": ""}).partition == ""


def test_ports_fall_back_and_never_collide() -> None:
    bad = TransportSettings.from_env({"GZ_DISCOVERY_MSG_PORT": "x", "GZ_DISCOVERY_SRV_PORT": "-3"})
    assert (bad.msg_port, bad.srv_port) == (10317, 10318)
    equal = TransportSettings.from_env(
        {"GZ_DISCOVERY_MSG_PORT": "2000", "GZ_DISCOVERY_SRV_PORT": "2000"}
    )
    assert (equal.msg_port, equal.srv_port) == (2000, 2001)
    top = TransportSettings.from_env(
        {"GZ_DISCOVERY_MSG_PORT": "65535", "IGN_DISCOVERY_SRV_PORT": "65535"}
    )
    assert (top.msg_port, top.srv_port) == (65535, 65534)


def test_hwm_and_implementation() -> None:
    env = {
        "GZ_TRANSPORT_RCVHWM": "5",
        "IGN_TRANSPORT_SNDHWM": "7",
        "GZ_TRANSPORT_IMPLEMENTATION": "Zenoh",
    }
    settings = TransportSettings.from_env(env)
    assert (settings.rcvhwm, settings.sndhwm, settings.implementation) == (5, 7, "zenoh")


def test_default_partition_uses_user_first() -> None:
    assert default_partition({"USER": "bob"}).endswith(":bob")
    assert ":" in default_partition({})


def test_max_message_size() -> None:
    assert TransportSettings.from_env({}).max_message_size == DEFAULT_MAX_MESSAGE_SIZE
    assert DEFAULT_MAX_MESSAGE_SIZE < 200_000_000  # the attack's frames are refused
    assert DEFAULT_MAX_MESSAGE_SIZE > 3840 * 2160 * 8  # a 4K image of 8 bytes per pixel is not
    env = {"GZ_TRANSPORT_MAX_MESSAGE_SIZE": "1000", "IGN_TRANSPORT_MAX_MESSAGE_SIZE": "9"}
    assert TransportSettings.from_env(env).max_message_size == 1000
    assert TransportSettings.from_env({"IGN_TRANSPORT_MAX_MESSAGE_SIZE": "9"}).max_message_size == 9
    for bad in ("-1", "lots", "0"):  # there is always a limit
        settings = TransportSettings.from_env({"GZ_TRANSPORT_MAX_MESSAGE_SIZE": bad})
        assert settings.max_message_size == DEFAULT_MAX_MESSAGE_SIZE


def test_credentials_need_both_names_and_stay_out_of_repr() -> None:
    both = {"GZ_TRANSPORT_USERNAME": "u", "GZ_TRANSPORT_PASSWORD": "p"}
    assert TransportSettings.from_env(both).credentials == ("u", "p")
    fortress = {"IGN_TRANSPORT_USERNAME": "u", "IGN_TRANSPORT_PASSWORD": "p"}
    assert TransportSettings.from_env(fortress).credentials == ("u", "p")
    assert TransportSettings.from_env({"GZ_TRANSPORT_USERNAME": "u"}).credentials is None
    assert TransportSettings.from_env({**both, "GZ_TRANSPORT_PASSWORD": ""}).credentials is None
    assert "p'" not in repr(TransportSettings.from_env(both))


def test_the_default_receive_queue_shrinks_with_the_topics_planned_at_start() -> None:
    """A few topics keep gz-transport's 1000 messages a pipe; a fleet's topics share about
    64 MiB of small messages at 9 KiB each (libzmq's read buffer), at least 50 a pipe."""
    assert [planned_rcvhwm(n) for n in (0, 1, 7, 8, 41, 101, 145, 201, 10_000)] == [
        1000, 1000, 1000, 910, 177, 72, 50, 50, 50
    ]  # fmt: skip
    assert TransportSettings.from_env({}, planned_subscriptions=201).rcvhwm == 50
    assert TransportSettings.from_env({}, planned_subscriptions=1).rcvhwm == 1000


def test_a_receive_hwm_the_user_sets_wins_over_the_planned_one() -> None:
    for name in ("GZ_TRANSPORT_RCVHWM", "IGN_TRANSPORT_RCVHWM"):
        settings = TransportSettings.from_env({name: "300"}, planned_subscriptions=201)
        assert settings.rcvhwm == 300


def test_a_bad_value_is_named_by_the_variable_set_and_the_default_in_words(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """The warning said 'TRANSPORT_RCVHWM' (no such variable) and 'using -1' (a marker)."""
    with caplog.at_level(logging.WARNING):
        settings = TransportSettings.from_env(
            {"GZ_TRANSPORT_RCVHWM": "abc", "IGN_DISCOVERY_MSG_PORT": "70000"},
            planned_subscriptions=1,
        )
    assert settings.rcvhwm == planned_rcvhwm(1)
    assert [record.getMessage() for record in caplog.records] == [
        "ignoring IGN_DISCOVERY_MSG_PORT='70000': not a port number; using 10317",
        "ignoring GZ_TRANSPORT_RCVHWM='abc': not a non-negative integer; using the default",
    ]
