"""transport/zenoh."""
