"""The set-up waits for a package manager that holds dpkg's lock, then installs (tools/apt_get.sh).

A real lock on /var/lib/dpkg/lock-frontend, taken the way apt and dpkg take it (an fcntl lock),
by another process; apt-get then asked to install a package the set-up has installed already
(cmake), which needs that lock but no download. Needs root, as the set-up's installs do.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[2] / "tools"
FRONTEND_LOCK = "/var/lib/dpkg/lock-frontend"

#: Holds the lock until a line comes on stdin; says "held" once it has it.
HOLDER = f"""
import fcntl, sys
lock = open({FRONTEND_LOCK!r}, "w")
fcntl.lockf(lock, fcntl.LOCK_EX)
print("held", flush=True)
sys.stdin.readline()
"""

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or not shutil.which("apt-get") or not shutil.which("lslocks"),
    reason="needs root, apt-get and lslocks (the set-up installs Debian packages as root only)",
)


def test_a_held_dpkg_lock_is_waited_for_then_the_install_runs() -> None:
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert holder.stdin is not None
    assert holder.stdout is not None
    try:
        assert holder.stdout.readline().strip() == "held"
        install = subprocess.Popen(
            ["bash", str(TOOLS / "apt_get.sh"), "install", "-y", "--no-install-recommends",
             "cmake"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            env={**os.environ, "DEBIAN_FRONTEND": "noninteractive", "APT_LOCK_WAIT": "600"},
        )  # fmt: skip
        assert install.stdout is not None
        first = install.stdout.readline()
        assert "another package manager holds its lock" in first
        assert f"{holder.pid} python" in first
        assert FRONTEND_LOCK in first
        assert install.poll() is None  # still waiting while the lock is held
        holder.stdin.write("release\n")
        holder.stdin.flush()
        holder.wait(timeout=60)
        rest = install.stdout.read()
        assert install.wait(timeout=600) == 0, rest
        assert "cmake is already the newest version" in rest
    finally:
        holder.kill()
        holder.wait()


def test_a_lock_held_past_the_wait_fails_naming_the_holder() -> None:
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert holder.stdout is not None
    try:
        assert holder.stdout.readline().strip() == "held"
        done = subprocess.run(
            ["bash", str(TOOLS / "apt_get.sh"), "install", "-y", "cmake"],
            capture_output=True, text=True, timeout=120, check=False,
            env={**os.environ, "DEBIAN_FRONTEND": "noninteractive", "APT_LOCK_WAIT": "1"},
        )  # fmt: skip
    finally:
        holder.kill()
        holder.wait()
    assert done.returncode == 1
    assert "still busy after 1 s" in done.stderr
    assert f"{holder.pid} python" in done.stderr
    assert "APT_LOCK_WAIT" in done.stderr
