"""Types of the compiled extension (_native.c)."""

class Program:
    """One pair's Gazebo -> ROS transcoder (docs/native.md §3)."""

    #: The protobuf fields the last ``to_cdr`` read (its work).
    steps: int
    #: The bytes of output buffer and scratch kept for the next ``to_cdr``.
    kept_bytes: int
    def __init__(self, schema: bytes, ops: bytes) -> None: ...
    def to_cdr(
        self, payload: bytes | bytearray | memoryview, /
    ) -> tuple[int, bytes | tuple[int, int] | None]: ...

class Encoder:
    """One pair's ROS -> Gazebo transcoder (docs/native.md §6)."""

    def __init__(self, words: bytes) -> None: ...
    def to_pb(self, cdr: bytes | bytearray | memoryview, /) -> tuple[int, bytes | None]: ...
