"""Why a topic carries nothing: a channel's flow state and the causes, in words to act on.

"The topics appear but no data comes" is the most common support question about the C++
bridge: a wrong type, a wrong partition, another Gazebo line, incompatible QoS, and the bridge
says nothing. Here the facts about one channel (what discovery and the ROS graph show, its own
counters) go in as a :class:`Situation`; its :class:`Flow` and the :class:`Finding` for each
cause come out, each naming the topic, what was expected, what was seen, and the fix. Pure
functions: the bridge gathers the facts (``explain.py``) and decides what to log.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.core.similar_topics import SUGGESTIONS, SimilarTopics
from ros_gz_bridge_py.msgs.names import GENERIC_TYPE, Spelling, respell, same_message, spelling_of
from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER, GraphEndpoint

#: A channel that passed a message this recently is flowing (at least; see :func:`flow`).
FLOWING_WINDOW = 5.0


class Flow(enum.Enum):
    """What a channel is doing, as users see it."""

    WAITING_GAZEBO = "waiting for Gazebo"
    WAITING_ROS = "waiting for ROS"
    FLOWING = "flowing"
    STALLED = "stalled"


@dataclass(frozen=True)
class Finding:
    """One reason a channel carries nothing (or carries to nobody)."""

    #: Stable while the cause lasts: what "once per cause" is counted by.
    key: str
    text: str
    #: A misconfiguration (raises the channel's status to WARN); False for a side that is
    #: simply not there yet (the channel waits, as it should).
    fault: bool = True


@dataclass(frozen=True)
class RosEndpoint:
    """A ROS publisher or subscriber at the other end of a channel (not the bridge's own)."""

    node: str
    msg_type: str
    #: Why its QoS cannot match the bridge's ("" when it can).
    qos_problem: str = ""
    #: Its QoS in a few words ("reliable, volatile, depth 10").
    qos: str = ""
    #: The ``qos_overrides`` of the bridge's endpoint that match it, as ``-p`` takes them
    #: after the topic's name (``publisher.durability:=transient_local``).
    qos_fixes: tuple[str, ...] = ()


#: What sets a channel's QoS profile where entries do (not image_bridge's, a parameter).
ENTRY_QOS_SETTING = "the entry's qos_profile"


@dataclass(frozen=True)
class TypeHints:
    """What the converter registry says about types, for the fixes a finding proposes."""

    #: (ROS type, Gazebo type) -> True when a pair converts them.
    pairs: Callable[[str, str], bool]
    #: Gazebo type -> the ROS types it pairs with.
    ros_types_for: Callable[[str], list[str]]
    #: ROS type -> the Gazebo types it pairs with.
    gz_types_for: Callable[[str], list[str]]
    #: The executable that chose the channels' types, where the user cannot ("image_bridge"):
    #: a fix that changes them points to parameter_bridge. "" when entries name their types.
    types_fixed_by: str = ""
    #: What the user changes to set a channel's QoS profile, as a fix names it.
    qos_setting: str = ENTRY_QOS_SETTING


@dataclass(frozen=True)
class Situation:
    """Everything known about one channel (or one ``--check`` entry) at one moment."""

    direction: Direction
    ros_topic: str
    ros_type: str
    #: The Gazebo topic name as discovery shows it (without the partition).
    gz_topic: str
    gz_type: str
    partition: str
    #: Every Gazebo endpoint of the topic in other processes, any partition.
    gz_endpoints: Sequence[GraphEndpoint]
    #: The ROS endpoints at the channel's other end: subscribers of a Gazebo->ROS channel,
    #: publishers of a ROS->Gazebo one.
    ros_endpoints: Sequence[RosEndpoint]
    #: Other Gazebo Transport processes heard at all.
    gz_peers: int
    #: Where the bridge looks for them (backend, partition, addresses).
    listening: str
    #: A Gazebo subscriber takes our messages (ROS->Gazebo; from NEW_CONNECTION or tokens).
    gz_subscriber_registered: bool = False
    #: Topics of other processes in our partition with endpoints of the role the channel
    #: needs (publishers to read, subscribers to write to), for "did you mean".
    gz_topics: Sequence[str] = ()
    #: Those of them whose endpoints of that role take the channel's Gazebo type.
    gz_typed: Sequence[str] = ()
    #: The Gazebo side had long enough to be there (the bridge listened a while, and the
    #: partition's other topics have been up a while): a side still absent is a fault then,
    #: not a simulator that starts after the bridge.
    overdue: bool = False
    #: No Gazebo process is heard now, but some were (for a while) since the bridge started.
    peers_lost: bool = False
    #: The channel's input side is open (a lazy channel without readers closes it).
    input_open: bool = True
    #: Seconds since the channel last passed a message; None if it never did.
    since_message: float | None = None
    #: The channel's usual time between messages, when known.
    interval: float | None = None
    #: The rule of discovered bridging that chose the types ("" for a configured entry).
    discovered_by: str = ""
    #: Discovery has listened long enough to have heard every Gazebo process. Until then,
    #: hearing none is no fault yet: the channel waits (a Gazebo endpoint absent), it is not
    #: told that no Gazebo process exists.
    peers_settled: bool = True
    #: The channel is one half of a bidirectional entry (the other half has its own).
    bidirectional: bool = False
    #: The bridge node's namespace ("/" or "" at the root): a Gazebo name outside it, when
    #: the simulator has the topic inside, is told how to put it there.
    ros_namespace: str = ""


def flow(situation: Situation) -> Flow:
    """The channel's state: flowing if it passed a message lately, else which side it waits
    for (Gazebo first: nothing can come from ROS to a Gazebo side that is not there).

    A channel whose Gazebo side is not there is waiting for it whatever it passed lately: a
    ROS->Gazebo channel's messages go nowhere without a Gazebo subscriber that takes them, and
    nothing more comes from a Gazebo publisher that left.
    """
    recent = max(FLOWING_WINDOW, 3 * (situation.interval or 0.0))
    if not _gazebo_side_ready(situation):
        return Flow.WAITING_GAZEBO
    if not situation.input_open:  # lazy, nobody reads: whatever it passed before
        return Flow.WAITING_ROS
    if situation.since_message is not None and situation.since_message <= recent:
        return Flow.FLOWING
    if not _ros_side_ready(situation):
        return Flow.WAITING_ROS
    return Flow.STALLED


def findings(situation: Situation, hints: TypeHints) -> list[Finding]:
    """Every cause that keeps ``situation``'s channel from carrying messages: the Gazebo
    side's first, as :func:`flow` names the side it waits for first."""
    found = [] if _gazebo_side_ready(situation) else _gazebo_findings(situation, hints)
    return found + _ros_findings(situation, hints)


# --- the Gazebo side -------------------------------------------------------------------------


def wanted_role(direction: Direction) -> str:
    """The Gazebo endpoints a channel needs: publishers to read, or subscribers to write to."""
    return PUBLISHER if direction is Direction.GZ_TO_ROS else SUBSCRIBER


def takes_ours(endpoint: GraphEndpoint, gz_type: str) -> bool:
    """Whether the endpoint takes ``gz_type``: a registration says the type it took, which
    is another entry's when two of ours share the Gazebo topic (Twist and String on /cmd)."""
    return endpoint.msg_type == GENERIC_TYPE or (
        bool(endpoint.msg_type) and same_message(endpoint.msg_type, gz_type)
    )


def _gazebo_side_ready(situation: Situation) -> bool:
    if situation.direction is Direction.ROS_TO_GZ:
        return situation.gz_subscriber_registered
    return any(
        e.role == PUBLISHER and e.partition == situation.partition
        and same_message(e.msg_type, situation.gz_type)
        for e in situation.gz_endpoints
    )  # fmt: skip


def _ros_side_ready(situation: Situation) -> bool:
    """ROS->Gazebo needs a ROS publisher of the type; a Gazebo->ROS channel needs nothing."""
    if situation.direction is Direction.GZ_TO_ROS:
        return True
    return any(e.msg_type == situation.ros_type for e in situation.ros_endpoints)


def _where(endpoint: GraphEndpoint) -> str:
    where = f"process {endpoint.process_uuid[:8]}"
    return f"{where} at {endpoint.location}" if endpoint.location else where


def _gazebo_findings(situation: Situation, hints: TypeHints) -> list[Finding]:
    role = wanted_role(situation.direction)
    mine = [
        e for e in situation.gz_endpoints if e.role == role and e.partition == situation.partition
    ]
    found = [_type_finding(situation, hints, e) for e in mine if _other_type(e, situation)]
    if role == SUBSCRIBER:
        found += [
            _declined_finding(situation, e) for e in mine if not e.msg_type and not e.registered
        ]
    if mine:
        return found
    elsewhere = [e for e in situation.gz_endpoints if e.partition != situation.partition]
    if elsewhere:
        needed = [e for e in elsewhere if e.role == role]
        return [_partition_finding(situation, needed or elsewhere, needed=bool(needed))]
    if situation.gz_peers == 0 and situation.peers_settled:
        return [_no_peer_finding(situation)]
    return [_absent_finding(situation, role)]


def _other_type(endpoint: GraphEndpoint, situation: Situation) -> bool:
    return bool(endpoint.msg_type) and not takes_ours(endpoint, situation.gz_type)


def _type_finding(situation: Situation, hints: TypeHints, endpoint: GraphEndpoint) -> Finding:
    seen = endpoint.msg_type
    verb = "publishes" if endpoint.role == PUBLISHER else "subscribes"
    # Either spelling works; propose the one the configuration already uses.
    written = respell(seen, spelling_of(situation.gz_type) or Spelling.GZ)
    ros_types = hints.ros_types_for(seen)
    if hints.pairs(situation.ros_type, seen):
        fix = _retyped(hints, f"set the Gazebo type (gz_type_name) to {written}")
    elif len(ros_types) == 1:
        fix = _retyped(
            hints, f"set the Gazebo type to {written} and the ROS type to {ros_types[0]}"
        )
    elif ros_types:
        fix = _retyped(
            hints,
            f"{written} pairs with {', '.join(ros_types)}: set the Gazebo type to {written} and "
            "the ROS type to one of those",
        )
    else:
        fix = f"no converter takes {seen} (bridge_types --print-pairs lists the pairs)"
    return Finding(
        f"gz-type:{endpoint.role}:{seen}",
        f"the Gazebo {endpoint.role} of {situation.gz_topic} ({_where(endpoint)}) {verb} "
        f"{seen}, but {_chosen(situation, situation.gz_type)}; {fix}",
    )


def _retyped(hints: TypeHints, fix: str) -> str:
    """``fix``, which changes an entry's types, where the executable lets the user do so."""
    if not hints.types_fixed_by:
        return fix
    return (
        f"{hints.types_fixed_by} cannot take other types: bridge the topic with "
        f"parameter_bridge ({fix})"
    )


def _chosen(situation: Situation, type_name: str) -> str:
    """How the bridge came to use ``type_name``: its configuration, or a rule of discovery."""
    if situation.discovered_by:
        return f"the bridge took {type_name} from discovery ({situation.discovered_by})"
    return f"the bridge is configured with {type_name}"


def _declined_finding(situation: Situation, endpoint: GraphEndpoint) -> Finding:
    return Finding(
        f"gz-declined:{endpoint.process_uuid}",
        f"a Gazebo subscriber of {situation.gz_topic} ({_where(endpoint)}) did not take "
        f"{situation.gz_type} under either spelling: it expects another message type; check "
        f"the type of the system or plugin that subscribes (gz topic -i -t {situation.gz_topic} "
        "on Harmonic and later shows it) and set the Gazebo type to it",
    )


def _partition_finding(
    situation: Situation, elsewhere: Sequence[GraphEndpoint], *, needed: bool
) -> Finding:
    """``elsewhere``: the endpoints of other partitions the channel needs (``needed``), else
    any of the topic there, which only suggest where the simulator runs (a Fortress subscriber
    is not seen until it has a publisher to connect to)."""
    partitions = sorted({e.partition for e in elsewhere})
    seen = "; ".join(
        f"'{p}': "
        + ", ".join(sorted({f"{e.role} {e.msg_type or '(type not announced)'}" for e in elsewhere
                            if e.partition == p}))
        for p in partitions
    )  # fmt: skip
    first = partitions[0]
    start = "start" if needed else "if the simulator runs there, start"
    return Finding(
        f"partition:{','.join(partitions)}",
        f"the Gazebo topic {situation.gz_topic} is alive in another partition ({seen}), but "
        f"the bridge uses partition '{situation.partition}'; {start} the bridge with "
        f"GZ_PARTITION={first} (and IGN_PARTITION={first} for Fortress), or give the "
        "simulator the bridge's partition",
    )


def _no_peer_finding(situation: Situation) -> Finding:
    compare = (
        "the same GZ_TRANSPORT_IMPLEMENTATION (zenoh), and Zenoh sessions that reach each "
        "other: the router both connect to running and reached at its endpoint, or peers that "
        "connect or listen where the other does (ZENOH_CONFIG, "
        "GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE; docs/zenoh.md)"
        if situation.listening.startswith("Zenoh")
        else "the same GZ_PARTITION (IGN_PARTITION on Fortress), GZ_IP/IGN_IP on a network both "
        "reach, and the same GZ_TRANSPORT_IMPLEMENTATION (zeromq or zenoh)"
    )
    still = "still " if situation.overdue else ""
    heard = (
        "the Gazebo Transport processes heard before are gone (a simulator that stopped, or a "
        "network that went away)"
        if situation.peers_lost
        else f"{still}no Gazebo Transport process is heard at all"
    )
    return Finding(
        "no-peer" + (":overdue" if situation.overdue else ""),
        f"{heard}; the bridge listens with {situation.listening}. Compare with the "
        f"simulator's environment: {compare}",
        fault=situation.overdue,
    )


def _heard(processes: int) -> str:
    """How many Gazebo processes discovery hears, whatever their partition."""
    counted = "1 Gazebo process" if processes == 1 else f"{processes} Gazebo processes"
    return f"{counted} heard in any partition"


def _absent_finding(situation: Situation, role: str) -> Finding:
    similar = _similar_topics(situation.gz_topic, situation.gz_topics)
    typed = [t for t in situation.gz_typed if t != situation.gz_topic]
    shown = ([t for t in similar if t in typed] + [t for t in typed if t not in similar])[
        :SUGGESTIONS
    ]
    hint = ""
    if shown:
        more = f" and {len(typed) - len(shown)} more" if len(typed) > len(shown) else ""
        hint = f"; Gazebo {role}s of {situation.gz_type} there: {', '.join(shown)}{more}"
    namespace = situation.ros_namespace.rstrip("/")
    inside = f"{namespace}/{situation.gz_topic.lstrip('/')}"
    named = similar + shown  # the name inside the namespace may be shown for its type
    similar = [t for t in similar if t not in shown]
    hint += f"; similar topics: {', '.join(similar)}" if similar else ""
    if namespace and inside in named:
        hint += (
            f"; Gazebo names do not take the bridge's namespace {namespace} unless "
            "expand_gz_topic_names is true (-p expand_gz_topic_names:=true, with the entry's "
            f"Gazebo name relative), or write {inside}"
        )
    other = PUBLISHER if role == SUBSCRIBER else SUBSCRIBER
    if not situation.bidirectional and any(
        e.role == other and e.partition == situation.partition for e in situation.gz_endpoints
    ):
        turned, symbol = ("ROS_TO_GZ", "]") if role == PUBLISHER else ("GZ_TO_ROS", "[")
        hint += (
            f"; a Gazebo {other} of {situation.gz_topic} is there: to carry messages the other "
            f"way, bridge it {turned} ('{symbol}' on the command line)"
        )
    overdue = (
        ", though the partition's other topics have been there a while: the simulator has "
        "none of this name"
        if situation.overdue
        else ""
    )
    return Finding(
        f"gz-absent:{role}" + (":overdue" if situation.overdue else ""),
        f"no Gazebo {role} of {situation.gz_topic} in partition '{situation.partition}' "
        f"({_heard(situation.gz_peers)}){overdue}{hint}",
        fault=situation.overdue,
    )


_similar_topics = SimilarTopics()


# --- the ROS side ----------------------------------------------------------------------------


def _ros_findings(situation: Situation, hints: TypeHints) -> list[Finding]:
    role = "subscriber" if situation.direction is Direction.GZ_TO_ROS else "publisher"
    found = []
    for endpoint in situation.ros_endpoints:
        if endpoint.msg_type != situation.ros_type:
            others = hints.gz_types_for(endpoint.msg_type)
            if situation.discovered_by:
                fix = _discovered_fix(situation, endpoint.msg_type, hints)
            elif hints.pairs(endpoint.msg_type, situation.gz_type):
                fix = _retyped(hints, f"set the ROS type (ros_type_name) to {endpoint.msg_type}")
            elif others:
                fix = _retyped(
                    hints,
                    f"{endpoint.msg_type} pairs with {', '.join(others)}: set the ROS and "
                    "Gazebo types to such a pair",
                )
            else:
                fix = f"no converter takes {endpoint.msg_type}"
            if not situation.discovered_by:  # the other way round: the ROS node changes
                verb = "subscribe to" if role == "subscriber" else "publish"
                fix += f"; or have {endpoint.node} {verb} {situation.ros_type}"
            found.append(
                Finding(
                    f"ros-type:{endpoint.node}:{endpoint.msg_type}",
                    f"the ROS {role} {endpoint.node} of {situation.ros_topic} uses "
                    f"{endpoint.msg_type}, but {_chosen(situation, situation.ros_type)}; "
                    f"{fix}",
                )
            )
        elif endpoint.qos_problem:
            found.append(
                Finding(
                    f"ros-qos:{endpoint.node}",
                    f"the ROS {role} {endpoint.node} of {situation.ros_topic} cannot match the "
                    f"bridge's QoS: {endpoint.qos_problem}; {_qos_fix(situation, endpoint, hints)}",
                )
            )
    return found


def _qos_fix(situation: Situation, endpoint: RosEndpoint, hints: TypeHints) -> str:
    """The parameters that give the bridge's endpoint the other end's QoS, as a command line
    takes them (a params file or a launch file's parameters take the same names)."""
    topic, uses = situation.ros_topic, f" ({endpoint.qos})" if endpoint.qos else ""
    if not endpoint.qos_fixes:
        return f"set {hints.qos_setting} (or qos_overrides.{topic}.*) to what it uses{uses}"
    overrides = " ".join(f"-p qos_overrides.{topic}.{fix}" for fix in endpoint.qos_fixes)
    return f"run the bridge with --ros-args {overrides} (or set {hints.qos_setting} to match)"


def _discovered_fix(situation: Situation, ros_type: str, hints: TypeHints) -> str:
    """The fix for a ROS endpoint of another type than a discovered bridge took."""
    if hints.pairs(ros_type, situation.gz_type):
        return (
            f"{ros_type} also pairs with {situation.gz_type}: write an entry with "
            f"ros_type_name {ros_type} (entries win over discovery)"
        )
    return (
        f"{ros_type} does not pair with {situation.gz_type}, which the Gazebo side takes: use "
        f"{situation.ros_type} in ROS, or write an entry with the types (entries win over "
        "discovery)"
    )
