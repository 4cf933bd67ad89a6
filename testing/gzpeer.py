"""Harness for tests that talk to real Ignition Transport 11 processes.

Three kinds of real peers are offered: our scriptable C++ peer (``testing/peer``, built here,
by ``make setup`` or else on first use, once per source hash, into
``.build/ign_peer/<hash>/``), and the Debian CLI
binaries ``ign-transport-topic`` / ``ign-transport-service`` (called directly; the ``ign``
Ruby wrapper is broken on bookworm). Every process started through this module is
remembered and killed by :func:`stop_processes` (the ``gz_processes`` fixture calls it at
test end: SIGTERM, then SIGKILL after a grace period).

The peer prints one machine-readable record per line (``READY``, ``MSG <type> <text>``,
``COUNT n BYTES b``, ``RESPONSE``/``FAILED``/``TIMEOUT``, ``STATS ...``); see
``testing/peer/main.cc``. Environment: processes inherit ours, so the loopback settings that
``tests/conftest.py`` puts in ``os.environ`` reach them.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import queue
import re
import shutil
import signal
import subprocess
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
PEER_SOURCE = ROOT / "testing" / "peer"
BUILD_ROOT = ROOT / ".build" / "ign_peer"
IGN_TOOLS = Path("/usr/libexec/ignition/transport11")
IGN_TOPIC = IGN_TOOLS / "ign-transport-topic"
IGN_SERVICE = IGN_TOOLS / "ign-transport-service"
#: Headers the peer build needs (from libignition-transport-dev / libignition-msgs-dev).
_HEADERS = (
    Path("/usr/include/ignition/transport11/ignition/transport.hh"),
    Path("/usr/include/ignition/msgs8/ignition/msgs.hh"),
)
_SOURCE_SUFFIXES = {".cc", ".hh", ".txt"}
_GRACE_SECONDS = 1.0
#: Seconds to wait for a finished process's last output to be read.
_DRAIN_SECONDS = 10.0


class PeerProcess(subprocess.Popen[str]):
    """A started process whose merged stdout/stderr lines are collected by a reader thread.

    ``lines`` holds everything printed so far; :func:`wait_for_line` consumes it in order.
    """

    def __init__(self, args: Sequence[str], env: Mapping[str, str] | None = None) -> None:
        super().__init__(
            list(args),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            bufsize=1,
            env=None if env is None else dict(env),
            start_new_session=True,
        )
        self.lines: list[str] = []
        self._cursor = 0
        self._arrived: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, name=f"peer-{self.pid}", daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.stdout is not None
        for line in self.stdout:
            self._arrived.put(line.rstrip("\n"))
        self._arrived.put(None)

    def _next_line(self, deadline: float) -> str | None:
        """The next unread line, waiting until ``deadline``; None at end of output."""
        while self._cursor >= len(self.lines):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError
            try:
                line = self._arrived.get(timeout=remaining)
            except queue.Empty:
                raise TimeoutError from None
            if line is None:
                self._arrived.put(None)
                return None
            self.lines.append(line)
        line = self.lines[self._cursor]
        self._cursor += 1
        return line

    def output(self) -> str:
        """Everything printed so far (for failure messages); all of it once the process has
        been waited for (the reader thread may still be draining the pipe when ``wait``
        returns, more so on a busy machine)."""
        if self.returncode is not None:
            self._reader.join(_DRAIN_SECONDS)
        with contextlib.suppress(queue.Empty):
            while (line := self._arrived.get_nowait()) is not None:
                self.lines.append(line)
            self._arrived.put(None)
        return "\n".join(self.lines)

    def stop(self, grace: float = _GRACE_SECONDS) -> None:
        """SIGTERM (the peer then prints its summary line), SIGKILL after ``grace`` seconds."""
        if self.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                self.send_signal(signal.SIGTERM)
            try:
                self.wait(grace)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(self.pid, signal.SIGKILL)
                self.wait()
        self._reader.join(grace)


_RUNNING: list[PeerProcess] = []


def tools_missing() -> list[str]:
    """What is missing for the peer tests (empty when everything is installed)."""
    missing = [str(path) for path in (IGN_TOPIC, IGN_SERVICE, *_HEADERS) if not path.exists()]
    missing += [tool for tool in ("cmake", "ninja", "c++") if shutil.which(tool) is None]
    return missing


def missing_reason() -> str:
    """Why the peer tests cannot run here ("" when they can)."""
    missing = tools_missing()
    if not missing:
        return ""
    return f"real ign-transport tools missing ({', '.join(missing)}); run tools/setup_peer.sh"


def require_peer() -> None:
    """Skip the calling test when the Debian tools are missing; fail instead under CI=true."""
    reason = missing_reason()
    if not reason:
        return
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(reason)
    pytest.skip(reason)


def _source_hash() -> str:
    digest = hashlib.sha256()
    for path in sorted(PEER_SOURCE.iterdir()):
        if path.suffix in _SOURCE_SUFFIXES:
            digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def peer_binary() -> Path:
    """The built C++ peer; builds it (cmake + ninja) when its sources changed.

    A file lock makes concurrent pytest processes build it only once.
    """
    require_peer()
    binary = _binary()
    if binary.exists():
        return binary
    BUILD_ROOT.mkdir(parents=True, exist_ok=True)
    with (BUILD_ROOT / ".lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not binary.exists():
            _build(binary.parent)
    return binary


def _binary() -> Path:
    """Where the peer of the current sources is (or will be) built."""
    return BUILD_ROOT / _source_hash() / "ign_peer"


def _build(build: Path) -> None:
    """Build in one persistent tree (ninja rebuilds only what changed), then keep a copy of
    the binary under the source hash so each version is built once."""
    tree = BUILD_ROOT / "tree"
    cache = tree / "CMakeCache.txt"
    if cache.exists() and f"CMAKE_HOME_DIRECTORY:INTERNAL={PEER_SOURCE}\n" not in cache.read_text():
        shutil.rmtree(tree)  # configured from another checkout: cmake refuses to reuse it
    steps = (
        ["cmake", "-S", str(PEER_SOURCE), "-B", str(tree), "-G", "Ninja"],
        ["cmake", "--build", str(tree)],
    )
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            msg = f"building the ign peer failed: {' '.join(step)}\n{done.stdout}{done.stderr}"
            raise RuntimeError(msg)
    build.mkdir(parents=True, exist_ok=True)
    partial = build / f"ign_peer.{os.getpid()}"
    shutil.copy2(tree / "ign_peer", partial)
    partial.replace(build / "ign_peer")
    for stale in BUILD_ROOT.iterdir():
        if stale.is_dir() and stale not in {build, tree}:
            shutil.rmtree(stale, ignore_errors=True)


def start_process(command: Sequence[str], env: Mapping[str, str] | None = None) -> PeerProcess:
    """Start ``command`` (any program), remembered for :func:`stop_processes`."""
    proc = PeerProcess(command, env)
    _RUNNING.append(proc)
    return proc


def start_peer(*args: str, env: Mapping[str, str] | None = None) -> PeerProcess:
    """Start the C++ peer with ``args`` (e.g. ``"echo", "/x", TYPE, "5"``)."""
    return start_process([str(peer_binary()), *args], env)


def stop_processes(grace: float = _GRACE_SECONDS) -> None:
    """Stop every process started through this module (SIGTERM, SIGKILL after ``grace``)."""
    while _RUNNING:
        _RUNNING.pop().stop(grace)


def _run(binary: Path, args: Sequence[str], timeout: float) -> subprocess.CompletedProcess[str]:
    require_peer()
    proc = start_process([str(binary), *args])
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout)
    proc.stop()
    return subprocess.CompletedProcess(proc.args, proc.returncode, proc.output(), "")


def ign_topic(*args: str, timeout: float = 10.0) -> subprocess.CompletedProcess[str]:
    """Run ``ign-transport-topic ARGS`` to completion (killed after ``timeout`` seconds).

    ``stdout`` holds the merged output; a run cut short has a negative ``returncode``.
    """
    return _run(IGN_TOPIC, args, timeout)


def ign_service(*args: str, timeout: float = 10.0) -> subprocess.CompletedProcess[str]:
    """Run ``ign-transport-service ARGS`` to completion (see :func:`ign_topic`)."""
    return _run(IGN_SERVICE, args, timeout)


def wait_for_line(proc: PeerProcess, pattern: str, timeout: float = 10.0) -> re.Match[str]:
    """The first not yet consumed output line of ``proc`` matching ``pattern`` (re.search).

    Lines before it are consumed too. Fails the test, with the output so far, when the
    process ends or ``timeout`` passes first.
    """
    regex = re.compile(pattern)
    deadline = time.monotonic() + timeout
    try:
        while (line := proc._next_line(deadline)) is not None:
            if match := regex.search(line):
                return match
    except TimeoutError:
        pass
    state = "still running" if proc.poll() is None else f"exit status {proc.returncode}"
    pytest.fail(
        f"no line matching {pattern!r} within {timeout} s from {proc.args!r} ({state}); "
        f"output:\n{proc.output()}"
    )


def wait_until(condition: Callable[[], bool], timeout: float, what: str) -> None:
    """Poll ``condition`` until true; fail the test naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.02)


def unique_name(stem: str) -> str:
    """A topic/service name no other test (or parallel run) uses: ``/<stem>_<pid>_<hex>``."""
    return f"/{stem}_{os.getpid()}_{uuid.uuid4().hex[:8]}"


@pytest.fixture
def gz_processes() -> Iterator[None]:
    """Stops every process the test started through this module, even when it fails."""
    yield
    stop_processes()


@pytest.fixture
def ign_peer() -> Path:
    """The built C++ peer (skips or, under CI=true, fails when the tools are missing)."""
    return peer_binary()


class Inbox:
    """Collects what a subscription callback receives, for assertions in the test thread.

    Pass the inbox itself as the callback: ``node.subscribe(topic, inbox)``.
    """

    def __init__(self) -> None:
        self._changed = threading.Condition()
        self._items: list[tuple[Any, Any]] = []

    def __call__(self, message: Any, info: Any) -> None:
        with self._changed:
            self._items.append((message, info))
            self._changed.notify_all()

    def items(self) -> list[tuple[Any, Any]]:
        """Everything received so far, as ``(message or payload, MessageInfo)`` pairs."""
        with self._changed:
            return list(self._items)

    def clear(self) -> None:
        """Forget what arrived so far."""
        with self._changed:
            self._items.clear()

    def wait_for(
        self, condition: Callable[[list[tuple[Any, Any]]], bool], timeout: float, what: str
    ) -> list[tuple[Any, Any]]:
        """Wait until ``condition(items)`` holds; fail the test naming ``what`` on timeout,
        with the last messages received (which one is missing tells a loss from a delay)."""
        if not self.holds_within(condition, timeout):
            items = self.items()
            last = ", ".join(" ".join(repr(message).split())[:80] for message, _ in items[-12:])
            pytest.fail(
                f"timed out after {timeout} s waiting for {what}; {len(items)} received"
                + (f", the last: {last}" if items else "")
            )
        return self.items()

    def holds_within(
        self, condition: Callable[[list[tuple[Any, Any]]], bool], timeout: float
    ) -> bool:
        """Whether ``condition(items)`` becomes true within ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while not condition(self._items):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._changed.wait(remaining)
            return True

    def wait_for_count(self, count: int, timeout: float) -> list[tuple[Any, Any]]:
        """Wait until at least ``count`` messages arrived."""
        return self.wait_for(lambda items: len(items) >= count, timeout, f"{count} messages")


def main() -> int:
    """``python -m testing.gzpeer``: build the C++ peer now, as ``make setup`` does, so that its
    first build (a minute or more on 2 cores) is set-up time and not the first test's. Without
    the Debian tools it says what is missing and exits 0: the tests that need them then skip,
    or fail under CI=true, with the same words."""
    reason = missing_reason()
    if reason:
        print(f"C++ test peer: not built, {reason}")
        return 0
    if _binary().exists():
        print("C++ test peer: up to date")
        return 0
    start = time.monotonic()
    peer_binary()
    print(f"C++ test peer: built ({time.monotonic() - start:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
