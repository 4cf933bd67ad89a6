"""Launch actions: ``RosGzBridge``, ros_gz_bridge's action for this bridge.

``from ros_gz_bridge_py.actions import RosGzBridge`` where a launch file had
``from ros_gz_bridge.actions import RosGzBridge``; in XML and YAML launch files its tag is
``ros_gz_bridge_py`` (ros_gz's is ``ros_gz_bridge``; both can be installed side by side).
Importing this package needs ROS ``launch``; the rest of ``ros_gz_bridge_py`` does not.
"""

from ros_gz_bridge_py.actions.ros_gz_bridge import RosGzBridge

__all__ = ["RosGzBridge"]
