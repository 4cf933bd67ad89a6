"""Types of the compiled extension (_native.c)."""

class Program:
    """One pair's Gazebo -> ROS transcoder (docs/native.md §3)."""

    def __init__(self, schema: bytes, ops: bytes) -> None: ...
    def to_cdr(self, payload: bytes | bytearray | memoryview, /) -> tuple[int, bytes | None]: ...
