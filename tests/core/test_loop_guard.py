"""``OwnPublications``: a sample is the bridge's own when its sequence number is one the
bridge's publisher used and its source timestamp falls inside that publish call.

A stand-in publisher stamps each sample inside ``publish`` as a DDS writer does. The same
rule at work with rclpy, where another node of the same process must still get through
(ros_gz issue #788), is ``test_channels.py``'s bidirectional test.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
from rclpy.serialization import serialize_message
from std_msgs.msg import Float64, String

from ros_gz_bridge_py.core.loop_guard import HISTORY, OwnPublications


class StampingPublisher:
    """Numbers its samples 1, 2, ... and stamps each during ``publish`` (wall clock, ns)."""

    def __init__(self) -> None:
        self.samples: list[dict[str, int]] = []

    def publish(self, _msg: Any) -> Any:
        self.samples.append(
            {
                "publication_sequence_number": len(self.samples) + 1,
                "source_timestamp": time.time_ns(),
            }
        )


def test_every_own_sample_is_recognised() -> None:
    own = OwnPublications()
    publisher = StampingPublisher()
    publish = own.wrap(publisher)
    for index in range(5):
        publish(index)
    assert [own.is_own(sample) for sample in publisher.samples] == [True] * 5


def test_another_writer_is_not_own_even_with_a_sequence_number_in_use() -> None:
    own = OwnPublications()
    ours = StampingPublisher()
    publish = own.wrap(ours)
    publish("a")
    publish("b")
    first, second = ours.samples
    after_every_call = time.time_ns() + 1_000_000
    assert own.is_own(first)
    # Another writer's sample 1, written after our publish calls.
    assert not own.is_own({**first, "source_timestamp": after_every_call})
    # Our number 2, but written before our call that used it began.
    assert not own.is_own({**second, "source_timestamp": first["source_timestamp"] - 1})
    # A number we never used.
    assert not own.is_own({**second, "publication_sequence_number": 3})


def test_a_sample_without_writer_information_is_not_own() -> None:
    own = OwnPublications()
    publisher = StampingPublisher()
    own.wrap(publisher)(None)
    assert not own.is_own({})
    assert not own.is_own({"publication_sequence_number": 1, "source_timestamp": 0})
    assert not own.is_own({"publication_sequence_number": 0, "source_timestamp": time.time_ns()})


def test_two_publishers_of_one_topic_each_keep_their_numbers() -> None:
    own = OwnPublications()
    first, second = StampingPublisher(), StampingPublisher()
    publish_first, publish_second = own.wrap(first), own.wrap(second)
    for index in range(3):
        publish_first(index)
        publish_second(index)
    assert all(own.is_own(sample) for sample in first.samples + second.samples)


def test_only_the_recent_history_is_remembered() -> None:
    own = OwnPublications()
    publisher = StampingPublisher()
    publish = own.wrap(publisher)
    for index in range(HISTORY + 2):
        publish(index)
    remembered = [own.is_own(sample) for sample in publisher.samples]
    assert remembered == [False, False] + [True] * HISTORY


def test_a_sample_seen_before_publish_returns_is_own() -> None:
    """With the write made with the GIL released, our subscription may take the sample while
    ``publish`` has not returned yet."""
    own = OwnPublications()
    seen: list[bool] = []

    class SeenDuringPublish(StampingPublisher):
        def publish(self, msg: Any) -> None:
            super().publish(msg)
            seen.append(own.is_own(self.samples[-1]))

    publish = own.wrap(SeenDuringPublish())
    publish("a")
    publish("b")
    assert seen == [True, True]


def test_a_publish_that_raises_uses_no_sequence_number() -> None:
    own = OwnPublications()
    publisher = StampingPublisher()
    refusing = True

    class SometimesRefusing:
        def publish(self, msg: Any) -> None:
            if refusing:
                raise ValueError(msg)
            publisher.publish(msg)

    publish = own.wrap(SometimesRefusing())
    with pytest.raises(ValueError, match="x"):
        publish("x")
    refusing = False
    publish("y")
    (sample,) = publisher.samples
    assert own.is_own(sample)
    assert not own.is_own({**sample, "publication_sequence_number": 2})


def test_watchers_hear_each_change_of_the_rcl_publishers() -> None:
    own = OwnPublications()
    heard: list[frozenset[int]] = []
    stop = own.watch_rcl_publishers(lambda: heard.append(own.rcl_publishers()))
    own.add_rcl_publisher(0x10)
    own.add_rcl_publisher(0x20)
    own.remove_rcl_publisher(0x10)
    stop()
    own.remove_rcl_publisher(0x20)
    assert heard == [frozenset({0x10}), frozenset({0x10, 0x20}), frozenset({0x20})]
    assert own.rcl_publishers() == frozenset()


class WritingPublisher(StampingPublisher):
    """Publishes objects as CDR and says which bytes it wrote, as ``WrittenPublisher`` does."""

    def publish(self, msg: Any) -> Any:
        super().publish(msg)
        return serialize_message(msg)


@pytest.mark.parametrize("publisher_class", [StampingPublisher, WritingPublisher])
def test_another_writer_in_step_with_ours_is_not_own(publisher_class: type[Any]) -> None:
    """Another node publishing right after each Gazebo message, numbered from 1 as ours are:
    its sample has our number and a stamp inside our publish call, but not our content.
    Each received form is judged: the object, and the CDR bytes of a raw subscription."""
    own = OwnPublications()
    own.guard()
    ours = publisher_class()
    publish = own.wrap(ours)
    for index in range(3):
        publish(String(data=f"gz {index}"))
    for index, sample in enumerate(ours.samples):
        mine, theirs = String(data=f"gz {index}"), String(data=f"ros {index}")
        assert own.is_own(sample, mine)
        assert own.is_own(sample, serialize_message(mine))
        assert not own.is_own(sample, theirs)
        assert not own.is_own(sample, serialize_message(theirs))


def test_published_cdr_is_compared_as_cdr() -> None:
    """A bulk channel publishes CDR bytes and its raw subscription receives CDR bytes; a
    large message is told apart by its ends (its header) as well as by its length."""
    own = OwnPublications()
    own.guard()
    ours = StampingPublisher()
    pixels = bytes(range(1, 256)) * 400
    frame = b"\x00\x01\x00\x00" + b"stamp 1 " + pixels
    own.wrap(ours)(frame)
    (sample,) = ours.samples
    assert own.is_own(sample, frame)
    assert not own.is_own(sample, b"\x00\x01\x00\x00" + b"stamp 2 " + pixels)
    assert not own.is_own(sample, frame + b"\x07")
    assert not own.is_own(sample, frame[:-1])


def test_a_nan_field_does_not_make_our_sample_foreign() -> None:
    """NaN is unequal to itself as a float, not as CDR: our own NaN sample is still ours."""
    own = OwnPublications()
    own.guard()
    ours = StampingPublisher()
    own.wrap(ours)(Float64(data=float("nan")))
    (sample,) = ours.samples
    assert own.is_own(sample, Float64(data=float("nan")))


def test_before_the_topic_is_guarded_number_and_time_decide() -> None:
    """Nothing is kept of publications made before a subscription judges the topic (the cost
    stays off topics that are not bridged both ways); their samples are judged as before."""
    own = OwnPublications()
    ours = StampingPublisher()
    publish = own.wrap(ours)
    publish(String(data="gz 0"))
    own.guard()
    publish(String(data="gz 1"))
    before, after = ours.samples
    assert own.is_own(before, String(data="ros 0"))
    assert not own.is_own(after, String(data="ros 1"))
    assert own.is_own(after, String(data="gz 1"))


def test_a_guarded_sample_seen_before_publish_returns_is_judged_by_content() -> None:
    own = OwnPublications()
    own.guard()
    seen: list[tuple[bool, bool]] = []

    class SeenDuringPublish(StampingPublisher):
        def publish(self, msg: Any) -> Any:
            super().publish(msg)
            sample = self.samples[-1]
            seen.append((own.is_own(sample, msg), own.is_own(sample, String(data="another"))))

    own.wrap(SeenDuringPublish())(String(data="a"))
    assert seen == [(True, False)]


class Numbered:
    """A publisher that numbers its publications itself, as a native pump does: it records
    what it is asked and answers that sample 1 is its own when it holds ``b"ours"``."""

    def __init__(self) -> None:
        self.guarded = False
        self.asked: list[Any] = []

    def is_own(self, sequence: int, stamp: int, received: bytes | None, /) -> bool:
        self.asked.append(received)
        return sequence == 1 and (received is None or b"ours" in bytes(received))

    def guard(self) -> None:
        self.guarded = True


def test_a_numbered_publisher_is_guarded_and_given_the_sample_as_cdr() -> None:
    own = OwnPublications()
    before, after = Numbered(), Numbered()
    own.add_numbered(before)
    own.guard()
    own.add_numbered(after)
    assert before.guarded
    assert after.guarded
    sample = {"publication_sequence_number": 1, "source_timestamp": time.time_ns()}
    assert own.is_own(sample, String(data="ours"))
    assert not own.is_own(sample, String(data="theirs"))
    assert before.asked[-1] == serialize_message(String(data="theirs"))
    assert own.is_own(sample)
    assert before.asked[-1] is None


def _padded(cdr: bytes, *, declared: bool) -> bytes:
    """``cdr`` padded to a multiple of 4 as a middleware may deliver it: with the count in the
    encapsulation options' last two bits and a byte of any value (XTypes; CycloneDDS), or with
    zeros and nothing said (Fast DDS before 2.1)."""
    pad = -len(cdr) % 4
    if declared:
        return cdr[:3] + bytes([cdr[3] | pad]) + cdr[4:] + b"\xff" * pad
    return cdr + bytes(pad)


@pytest.mark.parametrize("declared", [True, False])
def test_our_sample_padded_by_the_middleware_is_still_ours(declared: bool) -> None:
    own = OwnPublications()
    own.guard()
    ours = WritingPublisher()
    msg = String(data="gz 0")  # 4 + 4 + 5 bytes: 3 bytes short of a multiple of 4
    own.wrap(ours)(msg)
    (sample,) = ours.samples
    padded = _padded(serialize_message(msg), declared=declared)
    assert len(padded) == len(serialize_message(msg)) + 3
    assert own.is_own(sample, padded)
    assert not own.is_own(
        sample, _padded(serialize_message(String(data="ros 0")), declared=declared)
    )
