"""The project's reference pages stand on their own, and every citation of them is good.

* No file of the repository names the research notes the pages were written from (they live
  outside the repository): each fact is stated in ``docs/`` and cited from there.
* Every ``docs/<page>.md §N`` written anywhere names an existing page and a section that is a
  heading of it (``## 2.``, ``### 2.8``, ``#### 2.8.1``).
* A bare ``§N`` (a later citation in a file that has named its page once) resolves in one of
  the pages the file names; a docs page's bare ``§N`` in the page itself.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
THIS = Path(__file__).resolve()


#: How the notes outside the repository were named. A page of ours is always written with its
#: folder (``docs/conversions.md``), so a bare ``conversions.md`` is a note.
NOTE_NAMES = re.compile(
    r"shared/spec"
    r"|gz-transport-protocol\.md"
    r"|ros-gz-bridge-behaviour"
    r"|gz-msgs-versions"
    r"|(?<![\w/.-])(?:conversions|environment|style)\.md"
    r"|behaviour spec"
    r"|conversion spec"
)
SECTION = r"§\d+(?:\.\d+)*"
#: ``docs/protocol.md §2.3, §2.8.2`` or ``docs/behaviour.md §2.1-§2.4`` (the page may be
#: quoted: ``docs/protocol.md`` §4).
CITATION = re.compile(
    r"docs/(?P<page>[\w-]+)\.md`?(?P<sections>(?:\s*(?:,|-|/|and)?\s*" + SECTION + r")*)"
)
SECTION_NUMBER = re.compile(r"§(\d+(?:\.\d+)*)")
HEADING = re.compile(r"^#{1,6}\s+(\d+(?:\.\d+)*)\.?\s", re.MULTILINE)

_SKIPPED_DIRS = {
    ".git", ".venv", ".build", "build", "install", "log", "__pycache__", "node_modules",
    ".mypy_cache", ".ruff_cache", ".pytest_cache",
}  # fmt: skip
_MAX_SIZE = 2_000_000


def _text_files() -> Iterator[tuple[str, str]]:
    """(path relative to the root, text) of every text file of the repository but this one."""
    stack = [ROOT]
    while stack:
        folder = stack.pop()
        for path in sorted(folder.iterdir()):
            if path.is_dir():
                skipped = path.name in _SKIPPED_DIRS or path.name.startswith(".venv")
                if not skipped and not path.name.endswith(".egg-info"):
                    stack.append(path)
                continue
            if path.resolve() == THIS or not path.is_file() or path.stat().st_size > _MAX_SIZE:
                continue
            data = path.read_bytes()
            if b"\0" in data[:8192]:
                continue
            yield path.relative_to(ROOT).as_posix(), data.decode("utf-8", errors="replace")


@cache
def _files() -> tuple[tuple[str, str], ...]:
    return tuple(_text_files())


@cache
def _sections(page: str) -> frozenset[str] | None:
    """The section numbers of ``docs/<page>.md``; None if there is no such page."""
    path = DOCS / f"{page}.md"
    if not path.is_file():
        return None
    return frozenset(HEADING.findall(path.read_text(encoding="utf-8")))


def _problems(name: str, text: str) -> list[str]:
    problems = [f"names a note: {m.group(0)!r}" for m in NOTE_NAMES.finditer(text)]
    pages: set[str] = set()
    own = re.fullmatch(r"docs/([\w-]+)\.md", name)
    if own:
        pages.add(own.group(1))
    spans = []
    for match in CITATION.finditer(text):
        page = match.group("page")
        sections = _sections(page)
        if sections is None:
            problems.append(f"cites docs/{page}.md, which does not exist")
            continue
        pages.add(page)
        spans.append(match.span())
        problems += [
            f"cites docs/{page}.md §{number}, which has no such heading"
            for number in SECTION_NUMBER.findall(match.group("sections"))
            if number not in sections
        ]
    for match in SECTION_NUMBER.finditer(text):
        if any(start <= match.start() < end for start, end in spans):
            continue
        number = match.group(1)
        if not pages:
            problems.append(f"cites §{number} without naming a docs page")
        elif not any(number in (_sections(page) or ()) for page in pages):
            named = ", ".join(f"docs/{page}.md" for page in sorted(pages))
            problems.append(f"cites §{number}, which none of {named} has")
    return problems


def test_headings_are_found() -> None:
    assert {"1.1", "2.8.1", "2.9.3", "4.5", "5", "9", "9.4"} <= (_sections("protocol") or set())
    assert {"1.2", "3.5", "3.14", "4", "5"} <= (_sections("conversions") or set())


def test_problems_are_found() -> None:
    text = "see gz-transport-protocol.md §2.1 and (docs/protocol.md §2.8.1, §77) and §88"
    assert _problems("x.py", text) == [
        "names a note: 'gz-transport-protocol.md'",
        "cites docs/protocol.md §77, which has no such heading",
        "cites §88, which none of docs/protocol.md has",
    ]
    assert _problems("x.py", "(§2.1)") == ["cites §2.1 without naming a docs page"]
    assert _problems("x.py", "(docs/conversions.md §3.5) and docs/conversions.md") == []
    assert _problems("x.py", "docs/nowhere.md") == ["cites docs/nowhere.md, which does not exist"]


def test_every_citation_is_good() -> None:
    report = [f"{name}: {problem}" for name, text in _files() for problem in _problems(name, text)]
    assert not report, "\n".join(report)
