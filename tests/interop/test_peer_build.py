"""``python -m testing.gzpeer``, which ``make setup`` runs: the C++ peer is built before the
suite, and a second run only checks it; without the Debian tools it says what is missing and
lets the set-up go on."""

from __future__ import annotations

import subprocess
import sys

import pytest

from testing import gzpeer
from testing.gzpeer import ROOT, peer_binary


def test_a_built_peer_is_only_checked() -> None:
    binary = peer_binary()

    done = subprocess.run(
        [sys.executable, "-m", "testing.gzpeer"],
        cwd=ROOT, capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip

    assert done.returncode == 0, done.stderr
    assert done.stdout == "C++ test peer: up to date\n"
    assert binary.exists()


def test_missing_tools_are_named_and_do_not_stop_the_set_up(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(gzpeer, "tools_missing", lambda: ["cmake", "/usr/include/x.hh"])

    assert gzpeer.main() == 0

    assert capsys.readouterr().out == (
        "C++ test peer: not built, real ign-transport tools missing (cmake, /usr/include/x.hh); "
        "run tools/setup_peer.sh\n"
    )
