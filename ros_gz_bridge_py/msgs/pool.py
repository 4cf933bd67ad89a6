"""Message classes from the committed descriptor set ``gz_msgs.desc``.

A private descriptor pool keeps our gz.msgs definitions apart from any other protobuf code in
the process. The descriptor set is read once, on the first lookup.
"""

from __future__ import annotations

import functools
import threading
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from ros_gz_bridge_py.errors import UnsupportedTypeError
from ros_gz_bridge_py.msgs.names import canonical_type

DESCRIPTOR_SET_NAME = "gz_msgs.desc"

# Two pools would give two classes for one type (and CopyFrom between them fails), so the
# first load is serialised; classes are then unique per descriptor.
_LOAD_LOCK = threading.Lock()


def _pool() -> tuple[Any, tuple[str, ...]]:
    """The loaded pool and the sorted full names of its top-level messages."""
    with _LOAD_LOCK:
        return _load_pool()


@functools.cache
def _load_pool() -> tuple[Any, tuple[str, ...]]:
    # Beside this module, as pip installs package data (importlib.resources would also read it
    # from a zip, but importing it takes a tenth of the bridge's own start-up).
    data = Path(__file__).with_name(DESCRIPTOR_SET_NAME).read_bytes()
    file_set = descriptor_pb2.FileDescriptorSet.FromString(data)
    pool = descriptor_pool.DescriptorPool()
    names: list[str] = []
    # protoc --include_imports writes every file after its dependencies, as the pool requires.
    for file_proto in file_set.file:
        pool.AddSerializedFile(file_proto.SerializeToString())
        names.extend(f"{file_proto.package}.{m.name}" for m in file_proto.message_type)
    return pool, tuple(sorted(names))


def known_types() -> list[str]:
    """Sorted full names of every top-level message we define (gz.msgs.* and ignition.msgs.IMU)."""
    return list(_pool()[1])


def _resolve(type_name: str, names: tuple[str, ...]) -> str:
    """The pool name for ``type_name``: an exact match, else ignition.msgs.X read as gz.msgs.X."""
    if type_name in names:
        return type_name
    if canonical_type(type_name) in names:
        return canonical_type(type_name)
    message = (
        f"unknown Gazebo message type {type_name!r}: expected 'gz.msgs.Name' or "
        "'ignition.msgs.Name' with a name known to this bridge; list the known types with "
        "python -c 'from ros_gz_bridge_py.msgs import known_types; print(*known_types())'"
    )
    raise UnsupportedTypeError(message)


@functools.cache
def message_class(type_name: str) -> type[Any]:
    """Class for 'gz.msgs.X' or 'ignition.msgs.X'.

    ``ignition.msgs.X`` maps to ``gz.msgs.X`` unless an exact ``ignition.msgs.X`` exists (the
    Fortress IMU layout). Raises :class:`UnsupportedTypeError` for a name we do not define.
    """
    pool, names = _pool()
    descriptor = pool.FindMessageTypeByName(_resolve(type_name, names))
    cls: type[Any] = message_factory.GetMessageClass(descriptor)
    return cls
