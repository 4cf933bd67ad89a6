"""Where ``benchmarks.attacks`` writes its section: in place of the one there, whichever line it
starts on, and the other sections kept."""

from __future__ import annotations

from pathlib import Path

from benchmarks.attacks import write_section


def test_a_section_replaces_its_old_self_even_on_the_first_line(tmp_path: Path) -> None:
    page = tmp_path / "SOAK.md"
    write_section(page, "## Attacks\n\nfirst run\n")
    write_section(page, "## Attacks\n\nsecond run\n")
    # before: both runs, the second appended after the first
    assert page.read_text() == "## Attacks\n\nsecond run\n"


def test_a_section_between_others_is_replaced_and_a_new_one_added(tmp_path: Path) -> None:
    page = tmp_path / "SOAK.md"
    page.write_text("# Soak\n\n## Attacks\n\nold\n\n## Soak runs\n\nkept\n")
    write_section(page, "## Attacks\n\nnew\n")
    write_section(page, "## Attacks beside a load\n\nloaded\n")
    assert page.read_text() == (
        "# Soak\n\n## Attacks\n\nnew\n\n## Soak runs\n\nkept\n\n"
        "## Attacks beside a load\n\nloaded\n"
    )
