"""What ``benchmarks.fleet_cpu_map`` found at one fleet size, for the bridge or the same run's
rclpy ceiling (:class:`CpuMap`): per thread role its CPU, context switches and system calls,
and its perf samples, each read as µs per delivered message; and the figures it stores."""

from __future__ import annotations

import re
from collections import Counter, defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from benchmarks.bridge_threads import ORDER, RoleUse
from benchmarks.perf_profile import Profile

#: The names of each data plane's loop threads, to say which one was measured.
UNIFIED_NAMES = frozenset({"native-gz", "native-ros"})
TWO_LOOP_NAMES = frozenset({"gz-native", "ros-loop"})


@dataclass
class Delivered:
    """Messages the subscribers took in one window: Gazebo -> ROS, and ``cmd_vel`` sent."""

    gz_to_ros: int = 0
    commands: int = 0
    seconds: float = 0.0

    def messages(self, commanded: float) -> float:
        """Both directions, ``cmd_vel`` counted as the share of it that arrived."""
        return self.gz_to_ros + self.commands * commanded


@dataclass
class CpuMap:
    """One fleet size's readings."""

    robots: int
    load: float
    #: The ceiling's rclpy process instead of the bridge.
    ceiling: bool = False
    cpu_percent: float = 0.0
    clean: Delivered = field(default_factory=Delivered)
    roles: dict[str, RoleUse] = field(default_factory=dict)
    #: Share of the subscribers' commands that arrived (whole run).
    commanded: float = 1.0
    syscall_window: Delivered = field(default_factory=Delivered)
    syscalls: dict[str, Counter[str]] = field(default_factory=dict)
    profile_window: Delivered = field(default_factory=Delivered)
    profiles: dict[str, Profile] = field(default_factory=dict)
    #: The OS names of the bridge's threads, as seen, and its main thread's.
    names: frozenset[str] = frozenset()
    process: str | None = None
    #: Why a part was not measured.
    notes: list[str] = field(default_factory=list)

    def _messages(self, window: Delivered) -> float:
        return window.messages(self.commanded) or 1.0

    @property
    def rate(self) -> float:
        """Messages delivered a second in the clean window, both directions."""
        return self.clean.messages(self.commanded) / (self.clean.seconds or 1.0)

    def present(self) -> list[str]:
        """The roles that had threads, in table order."""
        others = sorted(role for role in self.roles if role not in ORDER)
        return [r for r in (*ORDER, *others) if r in self.roles and self.roles[r].threads]

    def us(self, role: str) -> float:
        """The role's CPU per delivered message in the clean window, µs."""
        use = self.roles.get(role)
        return 0.0 if use is None else use.cpu_s * 1e6 / self._messages(self.clean)

    @property
    def total_us(self) -> float:
        return sum(self.us(role) for role in self.roles)

    def per(self, role: str, read: Callable[[RoleUse], int]) -> float:
        """A count of the role's threads in the clean window, per delivered message."""
        use = self.roles.get(role)
        return 0.0 if use is None else read(use) / self._messages(self.clean)

    def calls(self, role: str) -> dict[str, float]:
        """The role's system calls per delivered message, by call, most first."""
        counted = self.syscalls.get(role, Counter())
        messages = self._messages(self.syscall_window)
        return {name: n / messages for name, n in counted.most_common()}

    def stage_us(self, role: str, stage: str) -> float:
        """A stage of ``role`` in µs per delivered message: its share of the role's samples
        times the role's µs per message in the clean window."""
        profile = self.profiles.get(role)
        return 0.0 if profile is None else profile.share(profile.stages[stage]) * self.us(role)

    def cut_us(self, role: str, cut: str) -> float:
        profile = self.profiles.get(role)
        return 0.0 if profile is None else profile.share(profile.cuts[cut]) * self.us(role)

    def part_us(self, role: str, stage: str, part: str) -> float:
        profile = self.profiles.get(role)
        return 0.0 if profile is None else profile.share(profile.parts[stage, part]) * self.us(role)

    def call_us(self, role: str, stage: str, call: str) -> float:
        """Time in system call ``call`` made within ``stage`` of ``role``, µs per message."""
        profile = self.profiles.get(role)
        return 0.0 if profile is None else profile.share(profile.calls[stage, call]) * self.us(role)

    def all_cut_us(self, cut: str) -> float:
        return sum(self.cut_us(role, cut) for role in self.profiles)

    def stage_totals(self) -> dict[str, float]:
        """Each stage over every thread, µs per delivered message."""
        totals: dict[str, float] = defaultdict(float)
        for role, profile in self.profiles.items():
            for stage in profile.stages:
                totals[stage] += self.stage_us(role, stage)
        return dict(totals)

    def items(self) -> list[tuple[float, str, str]]:
        """Every (µs per message, role, stage), biggest first: the stages do not overlap, so
        they add up to the bridge's CPU per message (where every role was profiled)."""
        found = [
            (self.stage_us(role, stage), role, stage)
            for role, profile in self.profiles.items()
            for stage in profile.stages
        ]
        return sorted(found, reverse=True)

    def loop_kind(self) -> str:
        if self.names & UNIFIED_NAMES:
            return "the unified native loop (issue 35; threads native-gz, native-ros)"
        if self.names & TWO_LOOP_NAMES:
            return (
                "the two native loops before issue 35's unification (threads gz-native, "
                "ros-loop, gz-fallback)"
            )
        return "a bridge without native loops (the Python path)"


def slug(role: str) -> str:
    """A role's name as a key of ``results.json``: ``gazebo_ros_loop``."""
    return re.sub(r"[^a-z0-9]+", "_", role.split(" (", maxsplit=1)[0].lower()).strip("_")


def numbers(maps: Sequence[CpuMap]) -> dict[str, float]:
    """The figures for ``benchmarks/results.json``: per size (``bridge<N>.``, the ceiling's
    ``ceiling<N>.``) the µs per delivered message, per role its µs, wake-ups and system calls
    per message, and the biggest stages."""
    stored: dict[str, float] = {}
    for found in maps:
        key = f"{'ceiling' if found.ceiling else 'bridge'}{found.robots}"
        stored[f"{key}.us_per_message"] = round(found.total_us, 2)
        for role in found.present():
            name = f"{key}.{slug(role)}"
            stored |= {
                f"{name}.us_per_message": round(found.us(role), 3),
                f"{name}.wakeups_per_message": round(found.per(role, lambda u: u.voluntary), 4),
                f"{name}.syscalls_per_message": round(sum(found.calls(role).values()), 3),
            }
        for us, role, stage in found.items()[:5]:
            stored[f"{key}.stage.{slug(role)}.{slug(stage)}"] = round(us, 3)
    return stored
