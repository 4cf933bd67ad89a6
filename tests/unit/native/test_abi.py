"""The native loops are used only with libraries laid out as their C code declares
(native/abi.py): libzmq 4.2 or later, and an rmw with Jazzy's 16-byte GIDs; the functions they
call are found by the names the extension gives, and passed to it by name."""

from __future__ import annotations

from typing import Any

import pytest

from ros_gz_bridge_py.native.abi import (
    find_functions,
    libzmq_path,
    rmw_layout_fits,
    rmw_problem,
    ros_functions,
    zmq_functions,
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


def test_the_functions_each_pump_calls_are_found_by_the_names_the_extension_gives(
    native: Any,
) -> None:
    """The extension's one list of what each type calls is what is looked up, and only it."""
    pump, ros_pump = zmq_functions(), ros_functions()
    assert pump is not None
    assert ros_pump is not None
    assert list(pump) == list(native.PUMP_FUNCTIONS)
    assert list(ros_pump) == list(native.ROS_PUMP_FUNCTIONS)
    assert all(pump.values())
    assert all(ros_pump.values())


def test_a_function_its_library_lacks_is_named() -> None:
    path = libzmq_path()
    assert path is not None
    found, why = find_functions(["zmq_msg_init", "zmq_no_such_function"], {"zmq": path})
    assert found == {}
    assert "zmq_no_such_function" in why
    found, why = find_functions(["rmw_get_gid_for_publisher"], {"zmq": path})  # no rmw given
    assert found == {}
    assert "rmw" in why


def test_a_pump_names_the_function_it_was_not_given(native: Any) -> None:
    """A missing or null address is refused at construction, by name, never called."""
    pump = zmq_functions()
    ros_pump = ros_functions()
    assert pump is not None
    assert ros_pump is not None
    missing = {name: address for name, address in pump.items() if name != "zmq_msg_recv"}
    with pytest.raises(ValueError, match="no address of zmq_msg_recv"):
        native.Pump(b"t", missing, 0, {}, 1, 0.0, 1)
    with pytest.raises(ValueError, match="no address of rcl_publish_serialized_message"):
        native.Pump(b"t", {**pump, "rcl_publish_serialized_message": 0}, 0, {}, 1, 0.0, 1)
    with pytest.raises(TypeError, match="dict"):
        native.Pump(b"t", list(pump.values()), 0, {}, 1, 0.0, 1)
    with pytest.raises(ValueError, match="no address of zmq_send"):
        native.RosPump({**ros_pump, "zmq_send": 0}, 1, 1, [], 0.0)
