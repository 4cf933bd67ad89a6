"""The gz.msgs protobuf messages, built at run time from our own ``.proto`` sources.

The ``.proto`` files under ``proto/`` are compiled by ``python -m ros_gz_bridge_py.msgs.regen``
into the committed descriptor set ``gz_msgs.desc``; message classes are made from it on first
use, so no generated ``_pb2`` modules exist.
"""

from __future__ import annotations

from ros_gz_bridge_py.msgs.names import GENERIC_TYPE
from ros_gz_bridge_py.msgs.pool import known_types, message_class

__all__ = ["GENERIC_TYPE", "known_types", "message_class"]
