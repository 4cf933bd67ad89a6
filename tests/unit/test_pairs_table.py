"""docs/pairs.md and the README's pairs block are what tools/gen_pairs_table.py generates."""

from __future__ import annotations

from pathlib import Path

import pytest

from tools.gen_pairs_table import (
    BEGIN,
    DOC,
    END,
    ROOT,
    TableError,
    builtin_registry,
    check,
    main,
    pairs_document,
    readme_block,
    replace_block,
)

README = ROOT / "README.md"


def test_docs_pairs_md_is_up_to_date() -> None:
    stale = check(DOC, builtin_registry())
    assert not stale, "docs/pairs.md is stale; run python tools/gen_pairs_table.py\n" + "".join(
        stale
    )


def test_readme_block_is_up_to_date() -> None:
    if BEGIN not in README.read_text():
        pytest.skip("README.md has no pairs block")
    stale = check(README, builtin_registry())
    assert not stale, (
        "README.md's pairs block is stale; run "
        "python tools/gen_pairs_table.py --update-readme README.md\n" + "".join(stale)
    )


def test_every_registered_pair_and_service_is_listed() -> None:
    registry = builtin_registry()
    document = pairs_document(registry)
    for pair in registry.pairs:
        assert f"| `{pair.ros_type}` | `{pair.gz_type}` |" in document
    for service in registry.services:
        assert f"| `{service.ros_type}` | `{service.gz_req_type}` |" in document
    rows = [line for line in document.splitlines() if line.startswith("| `")]
    assert len(rows) == len(registry.pairs) + len(registry.services)


def test_default_markers_follow_declaration_order() -> None:
    document = pairs_document(builtin_registry())
    assert "| `geometry_msgs/msg/Pose` | `gz.msgs.Pose` | default ROS type" in document
    assert "| `geometry_msgs/msg/PoseStamped` | `gz.msgs.Pose` |  |" in document
    assert "| `nav_msgs/msg/Odometry` | `gz.msgs.Odometry` | default Gazebo type" in document


def test_check_fails_on_a_stale_readme_block_and_update_fixes_it(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(f"# Title\n\n{BEGIN}\n| old | table |\n{END}\n\nAfter.\n")
    assert main(["--check", str(readme)]) == 1
    assert main(["--update-readme", str(readme)]) == 0
    assert main(["--check", str(readme)]) == 0
    text = readme.read_text()
    assert text.startswith("# Title\n\n")
    assert text.endswith(f"{readme_block(builtin_registry())}\n\nAfter.\n")


def test_a_file_without_markers_cannot_take_a_block() -> None:
    with pytest.raises(TableError, match="no <!-- pairs:begin -->"):
        replace_block("no markers here\n", "block", "X.md")
