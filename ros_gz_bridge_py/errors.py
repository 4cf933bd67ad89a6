"""One error root for the whole project, organised by phase.

Every error the project raises on purpose derives from :class:`BridgeError`. Errors that
describe bad input also derive from the matching stdlib type (``ValueError``,
``LookupError``, ``TimeoutError``) so callers can catch them either way. Messages are built
first and name the offending entry and the fix; only the top layer (the node or the CLI)
decides between "log and skip" and "fail".
"""

from __future__ import annotations

import re

#: Where in rcl's C sources an error was raised (", at /src/rcl/arguments.c:352"): rclpy's
#: errors end with it, and it names nothing the user wrote; messages drop it.
RCL_SOURCE_LOCATION = re.compile(r", at \S+:\d+")


class BridgeError(Exception):
    """Root of every error raised by ros_gz_bridge_py."""


class ConfigError(BridgeError, ValueError):
    """A bridge configuration (argument, YAML entry, parameter) is invalid.

    ``source`` says where the entry came from, e.g. ``"bridge.yaml entry 3 (line 12)"`` or
    ``"argument 2"``; it is prefixed to the message when present.
    """

    def __init__(self, message: str, source: str | None = None) -> None:
        self.message = message
        self.source = source
        super().__init__(f"{source}: {message}" if source else message)


class UnsupportedTypeError(ConfigError, LookupError):
    """No converter exists for a (ROS type, Gazebo type) pair, or a type name is unknown."""


class ConversionError(BridgeError, ValueError):
    """One message could not be converted; the channel counts it and goes on."""


class UndecodableError(ConversionError):
    """A payload that is not a valid serialized message of its type."""


class SizeMismatchError(ConversionError):
    """Sizes in a message that do not describe its data (an image's step and data, a point
    cloud's fields, steps and data)."""


class TransportError(BridgeError):
    """Gazebo Transport could not be initialised or an operation on it failed."""


class TransportTimeoutError(TransportError, TimeoutError):
    """A Gazebo Transport operation (a service call) did not complete in time."""


class ProtocolError(TransportError):
    """A Gazebo Transport wire-protocol rule was broken."""


class RemoteProtocolError(ProtocolError):
    """A peer sent something that breaks the wire protocol (malformed, wrong version, ...)."""


class LocalProtocolError(ProtocolError):
    """This process tried something the wire protocol does not allow (bad name, too large)."""
