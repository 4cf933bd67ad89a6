"""The instruction-count benchmark: its reading of callgrind's output, and one real count."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from benchmarks.instructions import Counted, Phase, inclusive, measure, rows, table, totals
from ros_gz_bridge_py import native

ANNOTATED = """\
--------------------------------------------------------------------------------
Ir
--------------------------------------------------------------------------------
1,200,000 (100.0%)  PROGRAM TOTALS
  347,697 (51.08%)  /src/native/transcode.c:rgb_to_cdr [/src/native/_native.so]
   40,000 ( 3.00%)  /src/native/transcode.c:rgb_to_cdr_helper [/src/native/_native.so]
"""


def test_reads_totals_and_a_functions_inclusive_count() -> None:
    assert totals("events: Ir\nsummary: 1234\ntotals: 1234\n") == 1234
    assert inclusive(ANNOTATED, "rgb_to_cdr") == 347_697  # not its longer-named neighbour
    assert inclusive(ANNOTATED, "rgb_to_pb") == 0
    with pytest.raises(ValueError, match="totals"):
        totals("events: Ir\n")


def test_rows_take_the_empty_calls_off_the_python_figures() -> None:
    def phase(path: str, direction: str = "gz_to_ros") -> Phase:
        return Phase("clock", direction if path != "empty" else "", path, 100, 2, 12)

    counted = [
        Counted(phase("empty"), 10_000, 0),  # 100 per call
        Counted(phase("native"), 50_000, 30_000),
        Counted(phase("python"), 250_000, 0),
    ]
    (row,) = rows(counted)
    assert (row.native, row.native_call, row.python) == (300, 400, 2400)
    before = [row.__class__(**{**row.__dict__, "native": 600.0})]
    shown = table([row], before, "abc1234")
    assert "| **300** | 600 | -50.0% |" in shown
    assert "| 8x |" in shown  # 2400 / 300


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_counts_a_real_conversion_under_callgrind(tmp_path: Path) -> None:
    if native.extension() is None:  # the extension-absent run of the suite
        pytest.skip(native.unavailable_reason())
    found = rows(measure(3, ["clock"], tmp_path / "run"))
    by_direction = {r.direction: r for r in found}
    assert set(by_direction) == {"gz_to_ros", "ros_to_gz"}
    for r in found:
        assert r.same_bytes is True
        assert r.native is not None
        assert 0 < r.native < r.python
