"""The built-in demo (``make demo``): a Python stand-in for Gazebo, the real bridge, a ROS client.

Modules: ``sim`` (robot kinematics and sensors as pure functions), ``world`` (the Gazebo side
on our transport), ``client`` (the rclpy side), ``report`` (statistics and output),
``processes`` (child processes), ``topics`` (names shared by both sides), ``__main__``
(orchestration).
"""
