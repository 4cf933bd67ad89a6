"""The ZeroMQ backend of every Gazebo line (docs/protocol-zmq-discovery.md §2)."""
