"""The Zenoh backend of gz-transport 15 (docs/protocol-zenoh.md §4)."""
