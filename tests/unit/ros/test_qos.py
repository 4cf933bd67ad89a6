"""ROS QoS of bridge endpoints (``ros/qos.py``)."""

from __future__ import annotations

import warnings

from rclpy.qos import HistoryPolicy

from ros_gz_bridge_py.ros.qos import endpoint_qos


def test_zero_depth_is_kept_without_rclpy_warning() -> None:
    """The config parser warns about a queue of 0 with its location; rclpy's unlocated
    warning, from building the profile or from qos_overrides setting the depth again, is not
    printed as well."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        profile = endpoint_qos(None, 0)
        profile.depth = 0  # as rclpy's qos_overrides do when the endpoint is created
    assert (profile.history, profile.depth) == (HistoryPolicy.KEEP_LAST, 0)
    assert [str(w.message) for w in caught] == []


def test_other_depths_keep_the_default_warning_filters() -> None:
    with warnings.catch_warnings():
        before = list(warnings.filters)
        assert endpoint_qos("SENSOR_DATA", 7).depth == 7
        assert warnings.filters == before
