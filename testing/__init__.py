"""What the tests (``tests/``) and the benchmarks (``benchmarks/``) both run things with.

The Gazebo peers (the C++ peer of ``testing/peer``, built on first use, and the ``ign`` tools),
started processes and their output lines, the bridge processes and the ROS-side processes
beside them, the fleet simulator's schedule, rogue Gazebo peers, the soak and the attacks,
polling, the loopback environment and readings of ``/proc``. It imports neither ``tests`` nor
``benchmarks`` (``tests/unit/test_folders.py``), and is not part of the wheel.
"""
