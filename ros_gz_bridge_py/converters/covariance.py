"""Covariance arrays: a fixed-size ROS ``float64[N]`` <-> a gz ``Float_V``.

Apart from the geometry_msgs module, which imports the geometry_msgs package (and with it numpy,
about 0.06 s), so that the native compilers, which name these helpers, load neither when a run
bridges no geometry type (docs/environment.md §3).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from ros_gz_bridge_py.converters._fields import Fill


def fill_gz_covariance(values: Iterable[float], gz_float_v: Any) -> None:
    """Append every ROS covariance value to a gz Float_V (float64 -> float32, lossy)."""
    gz_float_v.SetInParent()
    gz_float_v.data.extend(values)


def fill_ros_covariance(gz_float_v: Any, ros: Any) -> None:
    """The gz Float_V values into the ROS array when there are exactly as many, else zeros."""
    data = gz_float_v.data
    ros[:] = list(data) if len(data) == len(ros) else [0.0] * len(ros)


#: A fixed-size ROS covariance array <-> a gz Float_V; a gz one of another size reads as zeros.
COVARIANCE = Fill(fill_gz_covariance, fill_ros_covariance)
