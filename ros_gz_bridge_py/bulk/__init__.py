"""The bulk path: large messages converted without touching their bulk bytes.

An Image or a PointCloud2 is a few hundred bytes of metadata around megabytes of ``data``.
The object path (protobuf message -> converter -> rclpy message -> rclpy publish) copies those
megabytes about six times and holds the GIL through the DDS write. The bulk path instead:

- splits the Gazebo payload into its small fields and where the bulk field lies
  (:mod:`.protowire`), converts only the small fields with the pair's own converter, lets rclpy
  serialize that small message, and writes that CDR around the bulk bytes in the received frame
  where it has room (a Gazebo camera's frame: no copy), else splices them into a copy of the
  CDR (:mod:`.cdr`): at most one copy;
- publishes the CDR bytes through ``rcl_publish_serialized_message`` with the GIL released
  (:mod:`ros_gz_bridge_py.ros.serialized_publisher`), so other topics keep flowing during the
  DDS write;
- the other way, walks the serialized ROS message to the bulk field, converts the small rest,
  and appends the bulk bytes to the small protobuf payload: one copy.

The pair's converter of the small fields is told the bulk field's length: it checks the sizes
against it (the object path calls the same converter) and says what the output takes of the
bulk bytes, a prefix or rows without their padding (:class:`.path.Rows`).

:class:`BulkPath` (in :mod:`.path`) holds what one pair needs; the pair's module declares it.
"""
