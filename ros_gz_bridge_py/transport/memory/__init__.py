"""The in-memory backend: nodes of one process on a shared network object."""
