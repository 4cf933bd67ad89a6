"""The built extension for the native tests that use it as a fixture."""

from __future__ import annotations

from typing import Any

import pytest

from ros_gz_bridge_py.native import extension


@pytest.fixture(scope="module")
def native() -> Any:
    module = extension()
    if module is None:
        pytest.skip("the native extension is not built (test_native_path.py requires it in CI)")
    return module
