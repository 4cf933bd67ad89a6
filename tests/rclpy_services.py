"""The services an rclpy node offers of its own: its parameter services and the type description
service (``tests/unit/ros/test_bridge_node.py`` in process, ``tests/bridge/test_start_up.py``
through the bridge executables)."""

PARAMETER_SERVICES = frozenset(
    {
        "describe_parameters",
        "get_parameter_types",
        "get_parameters",
        "get_type_description",
        "list_parameters",
        "set_parameters",
        "set_parameters_atomically",
    }
)
