"""Compile our ``.proto`` sources into the committed descriptor set ``gz_msgs.desc``.

Usage: ``python -m ros_gz_bridge_py.msgs.regen [--check]``. ``--check`` compiles into a
temporary file and exits 1 if the committed file differs (stale or hand-edited). The output
is deterministic: inputs are sorted and no source info is included. ``protoc`` is taken from
the ``PROTOC`` environment variable, else from ``PATH``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ros_gz_bridge_py.errors import BridgeError

PACKAGE_DIR = Path(__file__).resolve().parent
PROTO_ROOT = PACKAGE_DIR / "proto"
DESCRIPTOR_SET = PACKAGE_DIR / "gz_msgs.desc"


def find_protoc() -> str:
    """Path of the protoc compiler; raises BridgeError if there is none."""
    protoc = os.environ.get("PROTOC") or shutil.which("protoc")
    if not protoc:
        message = "protoc not found: install protobuf-compiler or set PROTOC"
        raise BridgeError(message)
    return protoc


def proto_files(root: Path = PROTO_ROOT) -> list[str]:
    """Every ``.proto`` under ``root``, as sorted root-relative POSIX paths."""
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*.proto"))


def build_descriptor_set(root: Path, files: Sequence[str], output: Path) -> None:
    """Run protoc over ``files`` (relative to ``root``) into a FileDescriptorSet with imports."""
    command = [
        find_protoc(),
        f"--proto_path={root}",
        "--include_imports",
        f"--descriptor_set_out={output}",
        *files,
    ]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        message = f"protoc failed ({result.returncode}): {result.stderr.strip()}"
        raise BridgeError(message)


def main(argv: Sequence[str] | None = None) -> int:
    """Regenerate (or with ``--check`` verify) ``gz_msgs.desc``; the process exit status."""
    parser = argparse.ArgumentParser(prog="python -m ros_gz_bridge_py.msgs.regen")
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the committed descriptor set is stale"
    )
    args = parser.parse_args(argv)
    files = proto_files()
    if not args.check:
        build_descriptor_set(PROTO_ROOT, files, DESCRIPTOR_SET)
        print(f"wrote {DESCRIPTOR_SET} from {len(files)} files")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        fresh = Path(tmp) / DESCRIPTOR_SET.name
        build_descriptor_set(PROTO_ROOT, files, fresh)
        if DESCRIPTOR_SET.is_file() and fresh.read_bytes() == DESCRIPTOR_SET.read_bytes():
            print(f"{DESCRIPTOR_SET} is up to date")
            return 0
    print(f"{DESCRIPTOR_SET} is stale: run python -m ros_gz_bridge_py.msgs.regen", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
