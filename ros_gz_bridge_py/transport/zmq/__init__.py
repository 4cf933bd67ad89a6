"""transport/zmq."""
