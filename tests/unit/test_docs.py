"""The project's reference pages stand on their own, and every citation of them is good.

* No file of the repository names the research notes the pages were written from (they live
  outside the repository): each fact is stated in ``docs/`` and cited from there.
* Every ``docs/<page>.md §N`` written anywhere names an existing page and a section that is a
  heading of it (``## 2.``, ``### 2.8``, ``#### 2.8.1``).
* A bare ``§N`` (a later citation in a file that has named its page once) resolves in one of
  the pages the file names; a docs page's bare ``§N`` in the page itself.
* Every relative link of a Markdown page (``[text](path#anchor)``, images too) names a file or
  folder of the repository, and its anchor a heading of the page it names.
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
#: folder (``docs/conversions.md``), so a bare ``conversions.md`` is a note; a link's target
#: (``[docs/conversions.md](conversions.md)``, from a page of ``docs/``) is checked as a link.
NOTE_NAMES = re.compile(
    r"shared/spec"
    r"|gz-transport-protocol\.md"
    r"|ros-gz-bridge-behaviour"
    r"|gz-msgs-versions"
    r"|(?<![\w/.-])(?<!\]\()(?:conversions|environment|style)\.md"
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
#: ``[text](target)`` and ``![alt](target)``; the text may run over lines.
LINK = re.compile(r"\[[^\]]*\]\(([^()\s]+)\)")
FENCE = re.compile(r"^ {0,3}(```|~~~).*?^ {0,3}\1", re.MULTILINE | re.DOTALL)
CODE_SPAN = re.compile(r"`[^`\n]*`")

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
    assert {"1.1", "1.4", "5"} <= (_sections("protocol") or set())
    assert {"2", "2.3.1", "2.7"} <= (_sections("protocol-zmq-discovery") or set())
    assert {"2.8.1", "2.9.3"} <= (_sections("protocol-zmq-data") or set())
    assert {"4", "4.5"} <= (_sections("protocol-zenoh") or set())
    assert {"3", "9", "9.4"} <= (_sections("protocol-lines") or set())
    assert {"1.2", "4", "5"} <= (_sections("conversions") or set())
    assert {"3", "3.5", "3.14"} <= (_sections("conversions-per-package") or set())


def test_problems_are_found() -> None:
    text = "see gz-transport-protocol.md §2.9 and (docs/protocol-zmq-data.md §2.8.1, §77) and §88"
    assert _problems("x.py", text) == [
        "names a note: 'gz-transport-protocol.md'",
        "cites docs/protocol-zmq-data.md §77, which has no such heading",
        "cites §88, which none of docs/protocol-zmq-data.md has",
    ]
    assert _problems("x.py", "(docs/protocol.md §2.8.1)") == [
        "cites docs/protocol.md §2.8.1, which has no such heading"
    ]
    assert _problems("x.py", "(§2.1)") == ["cites §2.1 without naming a docs page"]
    assert _problems("x.py", "(docs/conversions-per-package.md §3.5) and docs/conversions.md") == []
    assert _problems("x.md", "see conversions.md, [docs/conversions.md](conversions.md)") == [
        "names a note: 'conversions.md'"
    ]
    assert _problems("x.py", "docs/nowhere.md") == ["cites docs/nowhere.md, which does not exist"]


def test_every_citation_is_good() -> None:
    report = [f"{name}: {problem}" for name, text in _files() for problem in _problems(name, text)]
    assert not report, "\n".join(report)


def _anchor(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation but ``-`` and ``_`` dropped,
    spaces made ``-``."""
    text = heading.strip().lower().replace("`", "")
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


@cache
def _anchors(path: Path) -> frozenset[str]:
    """The anchors of a Markdown page's headings (a repeated one also as ``-1``, ``-2``...)."""
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    seen: dict[str, int] = {}
    anchors = set()
    for line in text.splitlines():
        match = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        anchor = _anchor(match.group(1))
        count = seen.get(anchor, 0)
        seen[anchor] = count + 1
        anchors.add(anchor if count == 0 else f"{anchor}-{count}")
    return frozenset(anchors)


def _link_problems(name: str, text: str) -> list[str]:
    """What is wrong with the relative links of the Markdown page ``name`` (from the root)."""
    problems = []
    page = ROOT / name
    for match in LINK.finditer(CODE_SPAN.sub("", FENCE.sub("", text))):
        target = match.group(1)
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:
            continue
        path_part, _, anchor = target.partition("#")
        path = (page.parent / path_part).resolve() if path_part else page
        if not path.exists() or ROOT not in (path, *path.parents):
            problems.append(f"links {target}, which does not exist")
        elif anchor and path.suffix == ".md" and anchor not in _anchors(path):
            problems.append(f"links {target}, which has no such heading")
    return problems


def test_link_problems_are_found() -> None:
    page = "docs/protocol.md"
    assert _link_problems(page, "[a](conversions.md) [b](../README.md#the-two-commands)") == []
    assert _link_problems(page, "[a](nowhere.md) `[x](nowhere.md)`") == [
        "links nowhere.md, which does not exist"
    ]
    assert _link_problems(page, "[a](../README.md#no-such-heading)") == [
        "links ../README.md#no-such-heading, which has no such heading"
    ]
    assert _anchor("Node parameters (`parameter_bridge`, node name `ros_gz_bridge`)") == (
        "node-parameters-parameter_bridge-node-name-ros_gz_bridge"
    )


def test_every_relative_link_resolves() -> None:
    report = [
        f"{name}: {problem}"
        for name, text in _files()
        if name.endswith(".md")
        for problem in _link_problems(name, text)
    ]
    assert not report, "\n".join(report)
