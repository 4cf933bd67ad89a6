"""The native loops are used only with libraries laid out as their C code declares
(native/abi.py): libzmq 4.2 or later, and an rmw with Jazzy's 16-byte GIDs."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.native.abi import (
    rmw_layout_fits,
    rmw_problem,
    zmq_layout_fits,
    zmq_problem,
)


@pytest.mark.parametrize("version", [(4, 2, 0), (4, 3, 5), (5, 0, 0)])
def test_libzmq_with_64_byte_messages_fits(version: tuple[int, ...]) -> None:
    assert zmq_problem(version) == ""


@pytest.mark.parametrize("version", [(4, 1, 8), (4, 0, 10), (3, 2, 5)])
def test_older_libzmq_is_refused_saying_why(version: tuple[int, ...]) -> None:
    problem = zmq_problem(version)
    assert ".".join(map(str, version)) in problem
    assert "4.2 or later" in problem


@pytest.mark.parametrize(
    ("rclpy", "distro"),
    [("7.1.5", None), ("4.1.0", "iron"), ("9.1.0", "kilted"), (None, "jazzy"), (None, None),
     ("7.1.5", "humble")],  # rclpy as loaded wins over a stale ROS_DISTRO
)  # fmt: skip
def test_rmw_with_16_byte_gids_fits(rclpy: str | None, distro: str | None) -> None:
    assert rmw_problem(rclpy, distro) == ""


@pytest.mark.parametrize(("rclpy", "distro"), [("3.3.16", None), (None, "humble"), (None, "Foxy")])
def test_rmw_with_24_byte_gids_is_refused_saying_why(rclpy: str | None, distro: str | None) -> None:
    problem = rmw_problem(rclpy, distro)
    assert "24 bytes" in problem
    assert (rclpy or distro or "") in problem


def test_this_environment_fits() -> None:
    """The project's own environment (pyzmq's libzmq, Jazzy's rclpy) keeps the native loops."""
    assert zmq_layout_fits()
    assert rmw_layout_fits()
