"""Which Gazebo topics a "similar topics" hint names for a topic that is not there.

First the topics ending like it (a relative name in the wrong place: ``/robot1/odom`` for
``odom``), then those whose last name is spelt almost alike (``.../joint_state`` for
``/joint_states``: a simulator's names are long, and compared whole they never look close),
then close spellings of the whole name. Found once per topic while a list of topics stays the
same: the explainer asks again every few seconds for every channel waiting for Gazebo, and
difflib compares the name with every topic (101 waiting channels took 5-10% of a core at rest).
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from ros_gz_bridge_py.msgs.names import canonical_type
from ros_gz_bridge_py.transport.api import GraphEndpoint

#: How many similar Gazebo topic names a finding suggests.
SUGGESTIONS = 3
#: How alike two topics' last names must be (difflib's ratio) for one to be proposed for the
#: other when the whole names are close: names in one namespace share their prefix, which
#: alone made /robot1/clock "close" to /robot1/odom.
CLOSE_NAME = 0.6
#: How alike two last names must be for one to be proposed whatever the rest of the names.
ALIKE_NAME = 0.85
#: Lists of topics remembered at once (the explainer's two: publishers and subscribers).
_LISTS = 4


class SimilarTopics:
    """``similar(topic, topics)``: at most :data:`SUGGESTIONS` of ``topics`` like ``topic``."""

    def __init__(self) -> None:
        self._found: dict[tuple[str, ...], dict[str, list[str]]] = {}

    def __call__(self, topic: str, topics: Sequence[str]) -> list[str]:
        if not topics:
            return []
        listed = tuple(topics)
        found = self._found.get(listed)
        if found is None:
            if len(self._found) >= _LISTS:
                self._found.clear()
            found = self._found[listed] = {}
        similar = found.get(topic)
        if similar is None:
            similar = found[topic] = _similar(topic, listed)
        return list(similar)


def _similar(topic: str, topics: tuple[str, ...]) -> list[str]:
    name = _last_name(topic)
    others = [t for t in topics if t != topic]
    ending = [t for t in others if t.endswith("/" + name)]
    alike = sorted(
        (t for t in others if _alike(name, _last_name(t)) >= ALIKE_NAME),
        key=lambda t: -_alike(name, _last_name(t)),
    )
    close = [
        t
        for t in difflib.get_close_matches(topic, others, SUGGESTIONS)
        if _alike(name, _last_name(t)) >= CLOSE_NAME
    ]
    return list(dict.fromkeys(ending + alike + close))[:SUGGESTIONS]


def _alike(a: str, b: str) -> float:
    return difflib.SequenceMatcher(None, a, b).ratio()


def _last_name(topic: str) -> str:
    return topic.strip("/").rsplit("/", 1)[-1]


@dataclass(frozen=True)
class Offered:
    """The topics other processes have in the bridge's partition, by the role of their
    endpoints, and by role and message type: the names a hint may propose."""

    names: dict[str, tuple[str, ...]]
    typed: dict[tuple[str, str], tuple[str, ...]]

    def topics(self, role: str) -> tuple[str, ...]:
        return self.names.get(role, ())

    def of_type(self, role: str, gz_type: str) -> tuple[str, ...]:
        """Topics whose endpoints of ``role`` take ``gz_type`` (either spelling)."""
        return self.typed.get((role, canonical_type(gz_type)), ())


def offered_by_others(endpoints: Iterable[GraphEndpoint], partition: str) -> Offered:
    """What ``endpoints`` (another process's each, ``GzNode.graph``) offer in ``partition``."""
    names: dict[str, set[str]] = {}
    typed: dict[tuple[str, str], set[str]] = {}
    for endpoint in endpoints:
        if endpoint.partition.strip("/") != partition.strip("/"):
            continue
        names.setdefault(endpoint.role, set()).add(endpoint.topic)
        if endpoint.msg_type:
            key = (endpoint.role, canonical_type(endpoint.msg_type))
            typed.setdefault(key, set()).add(endpoint.topic)
    return Offered(
        {role: tuple(sorted(topics)) for role, topics in names.items()},
        {key: tuple(sorted(topics)) for key, topics in typed.items()},
    )
