"""The bridge's core tested in one process: real rclpy, the in-memory Gazebo Transport."""
