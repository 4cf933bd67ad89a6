"""The Zenoh backend of gz-transport 15 (docs/protocol.md §4)."""
