"""What the bridge costs and how it holds up, measured and written to BENCHMARKS.md and the
reports it lists, ``benchmarks/reports/`` (``make bench``: ``run.py``), and SOAK.md (``make soak``,
``make attacks``). A module per question, each writing its own report:

- ``conversion``: what converting one message costs, per pair and direction, in process;
- ``transport``: our Gazebo Transport node's throughput and latency against C++ ign-transport;
- ``images``, ``small_messages``: large and small messages through the bridge, beside the
  rclpy ceiling;
- ``sustained``: the highest 1080p rate the bridge sustains, and how late frames arrive;
- ``costs``: the bridge's CPU per delivered message, per type and direction;
- ``starvation``: whether ``/clock`` gets through while 1080p frames flood the same process;
- ``native_plane``: what the native data plane gives over the Python path, one module per
  experiment (``native_overload``, ``native_workload``, ``native_clock``, ``native_proxy``;
  ``native_paths`` is what they share);
- ``discovery``: how soon a new Gazebo topic exists in ROS, and what many discovered topics cost;
- ``startup``, ``first_call``: how soon the channels exist, and the first service call;
- ``fleet``: what a fleet of robots costs through one bridge process, as users run it, against
  the same run's rclpy ceiling (``fleet_rounds`` runs them, ``fleet_goals`` sums them up and
  judges them, ``fleet_ros`` is their ROS side and ``fleet_subscribers`` its processes);
- ``fleet_cpu_map``: where a fleet message's CPU goes in the bridge, per thread, stage and
  candidate, beside the same run's ceiling (not in ``make bench``; ``fleet_cpu_figures`` holds
  what it found, ``fleet_cpu_report`` writes it; it reads the bridge from outside through
  ``bridge_threads``, ``perf_syscalls`` and ``perf_profile``);
- ``socket_sharing``: what one SUB socket for a fleet's topics would save in libzmq against one
  per topic (not in ``make bench``);
- ``memory``: the bridge's memory under a long flood and beside a slow subscriber;
- ``profile_images``: where the time goes on the 1080p image path (not in ``make bench``);
- ``soak``, ``attacks``: SOAK.md from the runs of ``testing.soak`` and ``testing.attacks``.

What several share is named after what it is: ``harness`` (one flow through a bridge),
``bridged`` (flows on either backend), ``workers`` (the endpoint processes), ``payloads`` (the
messages), ``reference`` (the goals and the C++ figures quoted), ``tables``, ``report`` (the
reports), ``results`` (the stored figures), ``headline`` and ``plots``. Their own tests are in
``benchmarks/tests``.
"""
