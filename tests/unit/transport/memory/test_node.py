"""The in-memory backend's nodes that stand for one Gazebo line (``native``).

A native node keeps the rules of a gz process of its line (docs/protocol-lines.md §9.1): it
announces and asks for its own spelling only; a generic subscriber (``ign topic -e``, a log
recorder) registers with every publisher of the topic and decodes only the names its line
knows. Against such nodes our publisher (announced under both spellings) must send each
message once, in the spelling each line takes (§9.2). What every backend shares is in
``tests/unit/transport/test_node_contract.py``.
"""

from __future__ import annotations

import uuid

import pytest

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.transport import MessageInfo
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode

GZ, IGN = "gz.msgs.StringMsg", "ignition.msgs.StringMsg"
StringMsg = message_class(GZ)


class Inbox:
    def __init__(self) -> None:
        self.items: list[tuple[str, str]] = []

    def __call__(self, payload: bytes, info: MessageInfo) -> None:
        self.items.append((StringMsg.FromString(payload).data, info.msg_type))


def topic() -> str:
    return f"/memory_{uuid.uuid4().hex[:8]}"


def test_a_native_node_announces_and_asks_for_its_own_spelling(network: MemoryNetwork) -> None:
    ours = MemoryGzNode(network=network)
    fortress = MemoryGzNode(network=network, native=Spelling.IGNITION)
    name = topic()
    fortress.advertise(name, GZ)  # written gz.msgs, announced as Fortress names it
    assert [info.msg_type for info in ours.topic_info(name)] == [IGN]
    harmonic = MemoryGzNode(network=network, native=Spelling.GZ)
    only_gz = harmonic.advertise(name, GZ)
    fortress.subscribe(name, Inbox(), IGN)
    assert not only_gz.has_connections()  # a Fortress subscriber never takes gz.msgs


@pytest.mark.parametrize(("native", "spelling"), [(Spelling.IGNITION, IGN), (Spelling.GZ, GZ)])
def test_a_native_generic_subscriber_gets_each_message_once_in_its_spelling(
    network: MemoryNetwork, native: Spelling, spelling: str
) -> None:
    ours = MemoryGzNode(network=network)
    recorder = MemoryGzNode(network=network, native=native)
    name = topic()
    inbox = Inbox()
    recorder.subscribe(name, inbox)  # generic, like `ign topic -e`
    publisher = ours.advertise(name, GZ)  # announced as gz.msgs and as ignition.msgs
    assert publisher.wire_types() == {spelling}
    for index in range(3):
        publisher.publish(StringMsg(data=f"m{index}"))
    assert inbox.items == [(f"m{index}", spelling) for index in range(3)]


def test_a_native_generic_subscriber_drops_names_its_line_does_not_know(
    network: MemoryNetwork,
) -> None:
    harmonic = MemoryGzNode(network=network, native=Spelling.GZ)
    fortress = MemoryGzNode(network=network, native=Spelling.IGNITION)
    name = topic()
    inbox = Inbox()
    fortress.subscribe(name, inbox)
    publisher = harmonic.advertise(name, GZ)
    assert publisher.has_connections()  # it registers with every publisher of the topic
    publisher.publish(StringMsg(data="unknown here"))  # delivered on this thread, if at all
    assert inbox.items == []
