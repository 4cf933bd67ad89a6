"""The Zenoh session configuration, chosen as gz-transport 15 chooses it (docs/protocol-zenoh.md
§4.2).

1. ``ZENOH_CONFIG`` names a config file; if it is set but is not a readable regular file that
   parses, an error is logged and Zenoh's default configuration is used.
2. ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE="key=value;key=value"`` is applied on top: split on
   ``;``, the first ``=`` separates key and value, both trimmed of spaces and tabs, each
   applied with ``insert_json5``; entries without ``=`` or with an empty key are skipped, an
   entry Zenoh rejects is logged and skipped.

A caller (the bridge's parameter) may pass its own ``zenoh.Config`` instead of step 1 and
extra overrides, applied after the environment's. The default configuration is Zenoh's:
peer mode with multicast scouting, so keep tests on explicit loopback endpoints.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Iterable, Mapping

import zenoh

_LOG = logging.getLogger("ros_gz_bridge_py.transport")

CONFIG_FILE_ENV = "ZENOH_CONFIG"
OVERRIDE_ENV = "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE"

#: Overrides as gz writes them (``"k=v;k=v"``) or as key/value pairs.
Overrides = str | Mapping[str, str] | Iterable[tuple[str, str]]


def parse_overrides(text: str) -> list[tuple[str, str]]:
    """``"a = 1; b=\\"x\\""`` → ``[("a", "1"), ("b", '"x"')]``, skipping entries gz skips."""
    entries = []
    for entry in text.split(";"):
        key, sep, value = entry.partition("=")
        key = key.strip(" \t")
        if sep and key:
            entries.append((key, value.strip(" \t")))
    return entries


def apply_overrides(config: zenoh.Config, overrides: Overrides, source: str) -> None:
    """Insert each override into ``config``; a rejected one is logged (naming ``source``)."""
    if isinstance(overrides, str):
        entries: Iterable[tuple[str, str]] = parse_overrides(overrides)
    elif isinstance(overrides, Mapping):
        entries = overrides.items()
    else:
        entries = overrides
    for key, value in entries:
        try:
            config.insert_json5(key, value)
        except zenoh.ZError as error:
            _LOG.error(
                "ignoring Zenoh config override %s=%s from %s: %s", key, value, source, error
            )


def load_config_file(env: Mapping[str, str]) -> zenoh.Config:
    """The file named by ``ZENOH_CONFIG``, or Zenoh's default (logging why, if it was set)."""
    path = env.get(CONFIG_FILE_ENV)
    if path is None:
        return zenoh.Config()
    if not os.path.isfile(path):
        _LOG.error("Zenoh config file not found: %s; using the default configuration", path)
        return zenoh.Config()
    try:
        return zenoh.Config.from_file(path)
    except zenoh.ZError as error:
        _LOG.error(
            "Failed to parse Zenoh config file %s: %s; using the default configuration",
            path,
            error,
        )
        return zenoh.Config()


def session_config(
    config: zenoh.Config | None = None,
    overrides: Overrides | None = None,
    env: Mapping[str, str] | None = None,
) -> zenoh.Config:
    """The configuration a node opens its session with.

    ``config`` replaces the ``ZENOH_CONFIG`` step (it is modified in place by the overrides);
    ``overrides`` are applied after ``GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE``.
    """
    env = os.environ if env is None else env
    if config is None:
        config = load_config_file(env)
    env_overrides = env.get(OVERRIDE_ENV)
    if env_overrides:
        apply_overrides(config, env_overrides, OVERRIDE_ENV)
    if overrides is not None:
        apply_overrides(config, overrides, "the node's options")
    return config


#: Zenoh's receive limit (bytes) of a message reassembled from fragments, and its default.
RX_LIMIT_KEY = "transport/link/rx/max_message_size"
ZENOH_RX_LIMIT_DEFAULT = 1 << 30


def limit_message_size(config: zenoh.Config, limit: int) -> zenoh.Config:
    """Give Zenoh our maximum message size (GZ_TRANSPORT_MAX_MESSAGE_SIZE) as its receive
    limit, unless the configuration chose one: Zenoh then drops a larger message before
    reassembling it (without telling; messages that still arrive larger are counted by the
    node). gz sets nothing (docs/protocol-zenoh.md §4.2); the limit applies to what we receive."""
    if json.loads(config.get_json(RX_LIMIT_KEY)) == ZENOH_RX_LIMIT_DEFAULT:
        config.insert_json5(RX_LIMIT_KEY, str(limit))
    return config


def endpoints_config(
    mode: str, listen: Iterable[str] = (), connect: Iterable[str] = ()
) -> zenoh.Config:
    """A config that uses only the given endpoints: no multicast scouting, no gossip.

    For tests, benchmarks and set-ups where every endpoint is known, e.g.
    ``endpoints_config("client", connect=["tcp/10.0.0.5:7447"])``.
    """
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("scouting/gossip/enabled", "false")
    config.insert_json5("listen/endpoints", json.dumps(list(listen)))
    config.insert_json5("connect/endpoints", json.dumps(list(connect)))
    return config


def describe_session(config: zenoh.Config) -> str:
    """``Zenoh peer, connect [...], listen [...], multicast scouting on`` for users."""

    def value(key: str) -> str:
        try:
            return str(config.get_json(key))
        except zenoh.ZError:
            return "?"

    mode = value("mode").strip('"')
    mode = "peer" if mode in ("null", "?") else mode

    def endpoints(key: str) -> str:
        """Zenoh's defaults are per mode ({"router": [...], "peer": [...]}): this mode's."""
        text = value(key)
        try:
            given = json.loads(text)
        except ValueError:
            return text
        return json.dumps(given.get(mode, [])) if isinstance(given, dict) else text

    scouting = "off" if value("scouting/multicast/enabled") == "false" else "on"
    return (
        f"Zenoh {mode}, connect {endpoints('connect/endpoints')}, listen "
        f"{endpoints('listen/endpoints')}, multicast scouting {scouting}"
    )
