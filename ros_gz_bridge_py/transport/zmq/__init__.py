"""The ZeroMQ backend of every Gazebo line (docs/protocol.md §2)."""
