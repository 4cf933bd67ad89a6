"""The drop-oldest delivery queue: bounded by count and by bytes, never losing the newest."""

from __future__ import annotations

import threading
import time

from ros_gz_bridge_py.transport.delivery import DeliveryQueue, DropOldestQueue


def _blocked_queue(
    size: int, max_bytes: int
) -> tuple[DeliveryQueue[bytes], list[bytes], threading.Event]:
    """A queue whose handler blocks on its first item until the event is set."""
    handled: list[bytes] = []
    release = threading.Event()
    first = threading.Event()

    def handle(item: bytes) -> None:
        first.set()
        release.wait(10)
        handled.append(item)

    queue = DeliveryQueue(size, handle, "test", weigh=len, max_bytes=max_bytes)
    queue.put(b"first")
    assert first.wait(5)
    return queue, handled, release


def _drain(handled: list[bytes], count: int) -> None:
    deadline = time.monotonic() + 5
    while len(handled) < count and time.monotonic() < deadline:
        time.sleep(0.005)


def test_count_bound_drops_the_oldest() -> None:
    queue, handled, release = _blocked_queue(size=3, max_bytes=1 << 20)
    # put tells how many older items each one pushed out.
    results = [queue.put(bytes([i])) for i in range(6)]
    assert results == [0, 0, 0, 1, 1, 1]
    release.set()
    _drain(handled, 4)
    queue.close()
    assert handled == [b"first", b"\x03", b"\x04", b"\x05"]
    assert queue.dropped == 3


def test_byte_bound_keeps_the_newest_within_budget() -> None:
    queue, handled, release = _blocked_queue(size=100, max_bytes=25)
    for i in range(5):
        queue.put(bytes([i]) * 10)  # 10 bytes each: only two fit in 25
    release.set()
    _drain(handled, 3)
    queue.close()
    assert handled == [b"first", b"\x03" * 10, b"\x04" * 10]
    assert queue.dropped == 3


def test_one_item_larger_than_the_budget_is_still_delivered() -> None:
    queue, handled, release = _blocked_queue(size=10, max_bytes=4)
    queue.put(b"x" * 100)
    release.set()
    _drain(handled, 2)
    queue.close()
    assert handled == [b"first", b"x" * 100]
    assert queue.dropped == 0


def test_close_discards_pending_items_and_stops_the_thread() -> None:
    queue, handled, release = _blocked_queue(size=10, max_bytes=1 << 20)
    queue.put(b"pending")
    closer = threading.Thread(target=queue.close)
    closer.start()
    release.set()
    closer.join(5)
    assert not closer.is_alive()
    assert handled == [b"first"]


def test_on_start_runs_on_the_delivery_thread_before_the_first_item() -> None:
    events: list[tuple[str, int]] = []
    done = threading.Event()

    def handle(item: bytes) -> None:
        events.append((item.decode(), threading.get_ident()))
        done.set()

    queue = DeliveryQueue(
        10,
        handle,
        "test",
        weigh=len,
        on_start=lambda: events.append(("start", threading.get_ident())),
    )
    queue.put(b"item")
    assert done.wait(5)
    queue.close()
    assert [name for name, _ in events] == ["start", "item"]
    assert events[0][1] == events[1][1] != threading.get_ident()


def _sender_of(item: tuple[str, bytes]) -> str:
    return item[0]


def _weight(item: tuple[str, bytes]) -> int:
    return len(item[1])


def test_bytes_bound_takes_the_heaviest_senders_oldest_first() -> None:
    """A flood of large messages from one sender between a real publisher's small ones: over
    the bytes bound, the flooder's oldest go, the small ones all stay, in order."""
    queue: DropOldestQueue[tuple[str, bytes]] = DropOldestQueue(
        1000, weigh=_weight, max_bytes=100, source=_sender_of
    )
    dropped = 0
    for i in range(6):
        dropped += queue.put(("rogue", bytes([i]) * 40))
        dropped += queue.put(("real", bytes([i])))
    kept = [queue.get(block=False) for _ in range(len(queue))]
    assert [item for item in kept if item[0] == "real"] == [("real", bytes([i])) for i in range(6)]
    assert [item for item in kept if item[0] == "rogue"] == [
        ("rogue", bytes([4]) * 40),
        ("rogue", bytes([5]) * 40),
    ]
    assert kept[-1] == ("real", bytes([5]))  # the order of what stays is kept
    assert dropped == queue.dropped == 4
    assert queue.dropped_source == "rogue"


def test_without_a_source_the_bytes_bound_drops_the_oldest_of_all() -> None:
    queue: DropOldestQueue[tuple[str, bytes]] = DropOldestQueue(1000, weigh=_weight, max_bytes=100)
    for i in range(6):
        queue.put(("rogue", bytes([i]) * 40))
        queue.put(("real", bytes([i])))
    kept = [queue.get(block=False) for _ in range(len(queue))]
    assert ("real", bytes([0])) not in kept  # pushed out with the rogue's oldest
    assert queue.dropped_source is None


def test_the_heaviest_sender_is_the_one_holding_most_bytes_not_the_newest() -> None:
    queue: DropOldestQueue[tuple[str, bytes]] = DropOldestQueue(
        1000, weigh=_weight, max_bytes=100, source=_sender_of
    )
    queue.put(("camera", b"c" * 70))
    queue.put(("other", b"o" * 20))
    assert queue.put(("other", b"p" * 20)) == 1  # 110 bytes: the camera's 70 go
    kept = [queue.get(block=False) for _ in range(len(queue))]
    assert kept == [("other", b"o" * 20), ("other", b"p" * 20)]
    assert queue.dropped_source == "camera"
