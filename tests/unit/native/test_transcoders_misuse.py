"""The extension's own types refuse misuse from Python instead of crashing, and the extension
is built hardened (setup.py).

A pump reads a Program's (or Encoder's) words with the GIL released, so loading a second time
would free words a running loop reads: ``__init__`` runs once.
"""

from __future__ import annotations

import copy
import pickle
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

from tools.native_fuzz_programs import compiled_encoders, compiled_pairs


def _program_words() -> tuple[bytes, bytes]:
    _pair, compiled = compiled_pairs()[0]
    return compiled.schema, compiled.ops


def test_a_program_loads_once(native: Any) -> None:
    schema, ops = _program_words()
    program = native.Program(schema, ops)
    with pytest.raises(RuntimeError, match="loaded once"):
        program.__init__(schema, ops)
    with pytest.raises(RuntimeError, match="loaded once"):
        program.__init__(b"", b"")
    assert program.to_cdr(b"")[0] == 0  # still the first words


def test_an_encoder_loads_once(native: Any) -> None:
    _pair, words = compiled_encoders()[0]
    encoder = native.Encoder(words)
    with pytest.raises(RuntimeError, match="loaded once"):
        encoder.__init__(words)
    assert encoder.to_pb(b"\0\1\0\0" + bytes(64))[0] in (0, 1, 3)


def test_unloaded_objects_refuse_work(native: Any) -> None:
    program = native.Program.__new__(native.Program)
    with pytest.raises(ValueError, match="not loaded"):
        program.to_cdr(b"")
    encoder = native.Encoder.__new__(native.Encoder)
    with pytest.raises(ValueError, match="not loaded"):
        encoder.to_pb(b"")
    with pytest.raises(TypeError):
        native.Program(1, 2)


def test_a_failed_load_leaves_the_object_unloaded(native: Any) -> None:
    schema, ops = _program_words()
    program = native.Program.__new__(native.Program)
    with pytest.raises(ValueError, match="not a native program"):
        program.__init__(schema, b"")
    program.__init__(schema, ops)
    assert program.to_cdr(b"")[0] == 0


def test_the_extension_is_built_hardened_without_libdl(native: Any) -> None:
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("binutils' nm is missing")
    library = Path(native.__file__)
    symbols = subprocess.run([nm, "-D", str(library)], capture_output=True, text=True, check=True)
    undefined = {line.split()[-1].split("@")[0] for line in symbols.stdout.splitlines()}
    assert "__stack_chk_fail" in undefined  # -fstack-protector-strong
    assert not {name for name in undefined if name.startswith("dl")}


def test_copies_odd_buffers_and_attribute_writes_are_refused(native: Any) -> None:
    schema, ops = _program_words()
    program = native.Program(schema, ops)
    for copy_of in (copy.copy, copy.deepcopy, pickle.dumps):
        with pytest.raises(TypeError):
            copy_of(program)
    with pytest.raises(TypeError):
        program.to_cdr(None)
    with pytest.raises(BufferError):
        program.to_cdr(memoryview(b"abcd")[::2])
    with pytest.raises(AttributeError):
        program.steps = 0
    with pytest.raises(AttributeError):
        program.kept_bytes = 0
    assert program.to_cdr(bytearray())[0] == 0
