"""The Python half of fuzz/loop_fuzz.c: the reference its native pump is checked against.

The fuzz target embeds Python and imports this module. :class:`Host` holds a real
:class:`~ros_gz_bridge_py.transport.zmq.reader.NativeReader` (its socket owner's SUB socket is
made, never connected: no traffic) standing for the channel's reader, and plays the pump's side
of it (``NativeLoop``): what the reader learns goes to the C pump under test. ``judge`` is the
reader's own judgement of the frames the loop handed back; ``takes`` the socket owner's verdict
on a message, which the target compares with what the pump made of the same frames.
"""

from __future__ import annotations

import logging
from typing import Any

import zmq

from ros_gz_bridge_py.transport import MessageInfo
from ros_gz_bridge_py.transport.api import NativeHost, NativeSocketReader, Rejection
from ros_gz_bridge_py.transport.names import decompose
from ros_gz_bridge_py.transport.settings import TransportSettings
from ros_gz_bridge_py.transport.zmq.reader import NativeReader
from ros_gz_bridge_py.transport.zmq.socket_owner import Topic
from ros_gz_bridge_py.transport.zmq.wire import Frame

PARTITION = "loopfuzz"
#: The channel's topic, and topics the SUB socket also receives (ZeroMQ subscribes by prefix).
FQN = f"@/{PARTITION}@/model/x/pose"
#: A type every test topic takes but no program does (the pump refuses to learn it).
UNPROGRAMMED = "gz.msgs.Unprogrammed"


def quiet() -> None:
    """No warnings from the package (dropped messages, rejected senders): in the fuzz target,
    they would fill its output."""
    logging.getLogger("ros_gz_bridge_py").setLevel(logging.CRITICAL)


class Host:
    """A real native reader of ``fqn``, whose pump is the C ``Pump`` of the current input."""

    def __init__(self, fqn: str = FQN) -> None:
        self._context = zmq.Context()
        self.pump: Any = None
        self.types: frozenset[str] = frozenset()
        self.rejected = 0
        partition = (decompose(fqn) or (PARTITION, fqn))[0]
        topic = Topic(
            fqn,
            partition,
            accepts=lambda _sender, msg_type: msg_type in self.types,
            takes=lambda msg_type: msg_type in self.types,
            reject=self._reject,
            settings=TransportSettings(partition=partition),
            count=lambda *_args: None,
        )
        self.reader = NativeReader(
            self._context, topic, native=self, shared=None, deliver=lambda *_args: None, size=4
        )

    def reset(self, pump: Any, types: list[bytes]) -> None:
        """A new input: its pump, and the spellings the topic takes (and one no program takes)."""
        self.pump = pump
        self.types = frozenset({*(t.decode() for t in types), UNPROGRAMMED})
        self.reader._verdicts._infos.clear()

    def judge(self, frames: list[Frame]) -> None:
        """The reader's judgement of frames the loop handed back (it teaches the pump)."""
        self.reader._judge(frames)

    def takes(self, frames: list[Frame]) -> bool:
        """Whether the socket owner (the Python path's reference) delivers these frames."""
        return isinstance(self.reader._verdicts.verdict(frames), MessageInfo)

    def close(self) -> None:
        self.reader.close()
        self._context.term()

    def _reject(self, _reason: Rejection, _detail: str) -> None:
        self.rejected += 1

    # --- NativeLoop: the pump's side, as ChannelPump plays it -------------------------------

    def learn(self, sender: bytes, msg_type: bytes, *, take: bool) -> None:
        self.pump.learn(sender, msg_type, take)

    def attach(self, sock: int, monitor: int, host: NativeHost) -> None:
        """Not read by a loop here: the target turns the pump itself."""

    def socket_reader(self, sock: int, monitor: int, host: NativeHost) -> NativeSocketReader:
        """The host's reader has a socket of its own (``shared=None``): never asked."""
        raise NotImplementedError

    def attach_shared(self, reader: NativeSocketReader, host: NativeHost) -> None:
        """Never asked, as :meth:`socket_reader`."""
        raise NotImplementedError

    def detach(self) -> None:
        """Nothing attached."""

    def wake(self) -> None:
        """The target turns the pump on its own schedule."""

    def watch(self, size: int | None) -> None:
        """The target sets the watched size itself."""

    @property
    def received(self) -> int:
        return 0

    @property
    def dropped(self) -> int:
        return 0

    @property
    def dropped_sender(self) -> str:
        return ""


def spellings(gz_type: str) -> list[bytes]:
    """The wire spellings of a Gazebo type (gz.msgs.X and ignition.msgs.X)."""
    name = gz_type.removeprefix("gz.msgs.").removeprefix("ignition.msgs.")
    return [f"gz.msgs.{name}".encode(), f"ignition.msgs.{name}".encode()]


def payload(gz_type: str) -> bytes:
    """A message of ``gz_type`` with every field set, serialized."""
    from tools.native_fuzz_programs import distinctive  # noqa: PLC0415 - tools/ is on the path here

    return bytes(distinctive(gz_type).SerializeToString())
