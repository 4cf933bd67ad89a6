"""colcon's ament_python build runs ``setup.py``; the metadata is in ``pyproject.toml``."""

from setuptools import setup

setup()
