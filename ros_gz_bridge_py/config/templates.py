"""Placeholders in bridge configurations: ``${robot}`` filled from values the user gives.

Values come from the ``placeholders`` parameter (``-p placeholders:="[robot=r1, robot=r2]"``)
and from ``NAME=VALUE`` command-line arguments of ``parameter_bridge`` (``robot=r1,r2``). A
name given several values makes one entry per value, and an entry with several such names
one per combination, so one entry ``/model/${robot}/odometry`` serves every robot. A name with
no value is an error of the entry that uses it, naming the entry and how to give the value.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterable, Mapping, Sequence

from ros_gz_bridge_py.errors import ConfigError

#: ``${name}``: a letter or ``_``, then letters, digits or ``_``.
PLACEHOLDER = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}")
#: ``NAME=VALUE[,VALUE...]``, as a command-line argument or a ``placeholders`` item.
_ASSIGNMENT = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*=(.*)")

#: Values per placeholder name, in the order given.
Placeholders = Mapping[str, tuple[str, ...]]


def is_assignment(arg: str) -> bool:
    """True for a ``NAME=VALUE`` argument (a bridge argument always has an ``@``)."""
    return "@" not in arg and _ASSIGNMENT.fullmatch(arg) is not None


def parse_assignments(items: Iterable[str], where: str) -> dict[str, tuple[str, ...]]:
    """``["robot=r1,r2", "world=default"]`` -> ``{"robot": ("r1", "r2"), ...}``; a name
    given twice gets both sets of values.

    Raises:
        ConfigError: an item that is not ``NAME=VALUE`` (``where`` names its source).
    """
    values: dict[str, tuple[str, ...]] = {}
    for item in items:
        match = _ASSIGNMENT.fullmatch(item.strip())
        parts = [v.strip() for v in match.group(2).split(",")] if match else []
        if match is None or not all(parts):
            msg = (
                f"{where}: {item!r} is not a placeholder value; write NAME=VALUE or "
                "NAME=VALUE1,VALUE2 (NAME: letters, digits and _)"
            )
            raise ConfigError(msg)
        name = match.group(1)
        values[name] = tuple(dict.fromkeys((*values.get(name, ()), *parts)))
    return values


def merge(*sources: Placeholders) -> dict[str, tuple[str, ...]]:
    """The values of every source; later sources add to earlier ones."""
    merged: dict[str, tuple[str, ...]] = {}
    for source in sources:
        for name, values in source.items():
            merged[name] = tuple(dict.fromkeys((*merged.get(name, ()), *values)))
    return merged


def names_in(texts: Iterable[str]) -> list[str]:
    """The placeholder names used in ``texts``, each once, in order of appearance."""
    return list(dict.fromkeys(m.group(1) for text in texts for m in PLACEHOLDER.finditer(text)))


def missing_value(name: str, where: str) -> ConfigError:
    msg = (
        f"Could not parse entry: placeholder ${{{name}}} has no value; give it with "
        f'-p placeholders:="[{name}=VALUE]" or the argument {name}=VALUE'
    )
    return ConfigError(msg, where)


def combinations(names: Sequence[str], values: Placeholders, where: str) -> list[dict[str, str]]:
    """One substitution per combination of the values of ``names``.

    Raises:
        ConfigError: a name without a value (located at ``where``).
    """
    for name in names:
        if not values.get(name):
            raise missing_value(name, where)
    return [dict(zip(names, chosen, strict=True)) for chosen in itertools.product(
        *(values[name] for name in names)
    )]  # fmt: skip


def substitute(text: str, chosen: Mapping[str, str], where: str) -> str:
    """``text`` with every ``${name}`` replaced by ``chosen[name]``.

    Raises:
        ConfigError: a name not in ``chosen`` (located at ``where``).
    """

    def value(match: re.Match[str]) -> str:
        name = match.group(1)
        if name not in chosen:
            raise missing_value(name, where)
        return chosen[name]

    return PLACEHOLDER.sub(value, text)


def describe(chosen: Mapping[str, str]) -> str:
    """`` [robot=r1, world=w]`` for a source name ("" without placeholders)."""
    return f" [{', '.join(f'{k}={v}' for k, v in chosen.items())}]" if chosen else ""
