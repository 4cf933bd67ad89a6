"""Setuptools entry for the optional native data plane; the metadata is in ``pyproject.toml``.

colcon's ament_python build runs this file too. To learn the package's name and data files,
colcon reads ``setup.cfg`` instead of running this file when it finds the text ``setup()`` in
it (as it does here, in this sentence): running it would fail there, since colcon cannot read
back the ``python_requires`` that pyproject.toml gives. The extension is optional: where no C
compiler or Python headers exist, or the build fails, the package installs without it and the
bridge runs on the Python path (``ros_gz_bridge_py.native`` logs once why; docs/native.md §1).
"""

import importlib.util
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

CODES = Path(__file__).resolve().parent / "ros_gz_bridge_py" / "native" / "codes.py"

NATIVE_SOURCES = [
    "ros_gz_bridge_py/native/_native.c",
    "ros_gz_bridge_py/native/encode.c",
    "ros_gz_bridge_py/native/encode_load.c",
    "ros_gz_bridge_py/native/encode_write.c",
    "ros_gz_bridge_py/native/loop.c",
    "ros_gz_bridge_py/native/pb_read.c",
    "ros_gz_bridge_py/native/pump.c",
    "ros_gz_bridge_py/native/pump_loop.c",
    "ros_gz_bridge_py/native/pump_share.c",
    "ros_gz_bridge_py/native/ros_pump.c",
    "ros_gz_bridge_py/native/ros_pump_loop.c",
    "ros_gz_bridge_py/native/transcode.c",
    "ros_gz_bridge_py/native/transcode_load.c",
    "ros_gz_bridge_py/native/transcoders.c",
]


class BuildNative(build_ext):
    """Writes codes.h, the numbers the C transcoders read, from their one declaration
    (native/codes.py, loaded alone: the package's imports need what is not installed yet) into
    the build's temporary folder, which the compiler searches."""

    def build_extensions(self) -> None:
        spec = importlib.util.spec_from_file_location("ros_gz_bridge_codes", CODES)
        assert spec is not None
        assert spec.loader is not None
        codes = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(codes)
        generated = Path(self.build_temp)
        generated.mkdir(parents=True, exist_ok=True)
        codes.write_c_header(generated / "codes.h")
        for extension in self.extensions:
            extension.include_dirs.append(str(generated))
        super().build_extensions()


setup(
    cmdclass={"build_ext": BuildNative},
    ext_modules=[
        Extension(
            "ros_gz_bridge_py.native._native",
            sources=NATIVE_SOURCES,
            depends=[
                "ros_gz_bridge_py/native/_native.h",
                "ros_gz_bridge_py/native/codes.py",
                "ros_gz_bridge_py/native/encode.h",
                "ros_gz_bridge_py/native/encode_ops.h",
                "ros_gz_bridge_py/native/transcode.h",
                "ros_gz_bridge_py/native/transcode_ops.h",
                "ros_gz_bridge_py/native/wire.h",
            ],
            extra_compile_args=[
                "-O2",
                "-std=gnu11",
                "-Wall",
                "-Wextra",
                "-fvisibility=hidden",
                # The extension parses network input: canaries on every frame with arrays, and
                # glibc's checked memcpy/memset where sizes are known (needs -O1 or more).
                "-fstack-protector-strong",
                "-U_FORTIFY_SOURCE",
                "-D_FORTIFY_SOURCE=2",
            ],
            optional=True,
        )
    ],
)
