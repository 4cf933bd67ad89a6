"""The CPU map's readings and arithmetic: thread roles from OS names (both data planes' names),
a live thread's run time and wake-ups from /proc, perf's per-thread system call counts, perf
samples sorted into stages, parts and cross-cuts, and µs per delivered message from them."""

from __future__ import annotations

import argparse
import os
import threading
import time
from collections import Counter
from pathlib import Path

from benchmarks import perf_profile, perf_syscalls
from benchmarks.bridge_threads import MAIN, OTHER_PYTHON, RoleUse, by_role, read_threads, role_of
from benchmarks.fleet_cpu_figures import CpuMap, Delivered, numbers
from benchmarks.fleet_cpu_report import biggest, section

PID = 1000


def test_roles_come_from_the_os_names_of_either_data_plane() -> None:
    assert role_of("gz-native", 1001, PID) == role_of("native-gz", 1001, PID)
    assert role_of("gz-native", 1001, PID) == "Gazebo -> ROS loop"
    assert role_of("ros-loop", 1002, PID) == role_of("native-ros", 1002, PID)
    assert role_of("gz-fallback", 1003, PID) == role_of("native-fallback", 1003, PID)
    assert role_of("gz-sub /clock", 1004, PID) == "topic readers (Python, gz-sub)"
    assert role_of("ZMQbg/IO/0", 1005, PID) == "libzmq I/O"
    assert role_of("6/ZMQbg/IO/0", 1013, PID) == "libzmq I/O"  # the bulk path's context
    assert role_of("ZMQbg/Reaper", 1006, PID) == "libzmq other"
    assert role_of("dds.ev.0", 1007, PID) == "Fast DDS events"
    assert role_of("dds.shm.13913", 1008, PID) == "Fast DDS shared-memory receive"
    assert role_of("dds.shm.wdog", 1009, PID) == "Fast DDS other"
    assert role_of("parameter_bridg", PID, PID) == MAIN
    assert role_of("parameter_bridg", 1010, PID) == OTHER_PYTHON
    # A name no role knows: an unnamed Python thread's if it is the process's, else its own.
    assert role_of("parameter_bridg", 1011, PID, "parameter_bridg") == OTHER_PYTHON
    assert role_of("native-all7", 1012, PID, "parameter_bridg") == "other: native-allN"


def test_a_named_threads_run_time_and_wake_ups_are_read_from_proc() -> None:
    named, go = threading.Event(), threading.Event()
    finished, done = threading.Event(), threading.Event()

    def loop() -> None:
        Path(f"/proc/self/task/{threading.get_native_id()}/comm").write_text("native-gz")
        named.set()
        go.wait(30)
        for _ in range(20):  # 5 ms of CPU, then a sleep: a voluntary switch, a wake-up to come
            end = time.thread_time() + 0.005
            while time.thread_time() < end:
                pass
            time.sleep(0.001)
        finished.set()
        done.wait(30)  # a thread's readings are there while it lives

    pid = os.getpid()
    thread = threading.Thread(target=loop)
    thread.start()
    assert named.wait(30)
    before = read_threads(pid)
    go.set()
    assert finished.wait(30)
    after = read_threads(pid)
    done.set()
    thread.join()
    use = by_role(pid, before, after)["Gazebo -> ROS loop"]
    assert use.threads == 1
    assert use.names == frozenset({"native-gz"})
    assert use.cpu_s >= 0.095
    assert use.voluntary >= 20


PERF_STAT = """# started on Sat Nov 28 18:55:08 2026

gz-native-12740;9175;;syscalls:sys_enter_futex;318092113;100.00;;
gz-native-12740;54440;;syscalls:sys_enter_getpid;318092113;100.00;;
ZMQbg/IO/0-12738;13416;;syscalls:sys_enter_write;123719989;100.00;;
ZMQbg/Reaper-12737;<not counted>;;syscalls:sys_enter_write;0;100.00;;
gz-native-12740;70000;;raw_syscalls:sys_enter;318092113;100.00;;
ZMQbg/IO/0-12738;13416;;raw_syscalls:sys_enter;123719989;100.00;;
"""


def test_perf_stat_counts_are_read_per_thread_with_the_rest_as_other() -> None:
    assert perf_syscalls.parse(PERF_STAT) == {
        ("gz-native", 12740): {"futex": 9175, "getpid": 54440, "other": 6385},
        ("ZMQbg/IO/0", 12738): {"write": 13416},
        ("ZMQbg/Reaper", 12737): {},
    }


LIBZMQ = "/venv/site-packages/pyzmq.libs/libzmq-2f02442c.so.5.2.5"
NATIVE = "/repo/ros_gz_bridge_py/native/_native.cpython-311-x86_64-linux-gnu.so"
PYTHON = "/root/.pyenv/versions/3.11.7/lib/libpython3.11.so.1.0"
ROOT_FRAMES = f"""\
\t            6b9d pass (inlined)
\t            6b9d loop_run ({NATIVE})
\t          164525 method_vectorcall_VARARGS ({PYTHON})
\t           891f4 start_thread (/usr/lib/x86_64-linux-gnu/libc.so.6)
"""
PERF_SCRIPT = f"""gz-native 12199
\tffffffff816da390 do_sys_poll ([kernel.kallsyms])
\tffffffff816db4f1 __x64_sys_poll ([kernel.kallsyms])
\tffffffff821ed511 do_syscall_64 ([kernel.kallsyms])
\tffffffff81000130 entry_SYSCALL_64_after_hwframe ([kernel.kallsyms])
\t           fc26f __GI___poll (inlined)
\t           5e2c0 [unknown] ({LIBZMQ})
\t           8d70b zmq_msg_recv ({LIBZMQ})
\t            9371 pump_read ({NATIVE})
{ROOT_FRAMES}
gz-native 12199
\tffffffff81100000 _raw_spin_unlock_irqrestore ([kernel.kallsyms])
\tffffffff81100100 try_to_wake_up ([kernel.kallsyms])
\tffffffff81100200 __x64_sys_futex ([kernel.kallsyms])
\tffffffff821ed511 do_syscall_64 ([kernel.kallsyms])
\t           a0000 __new_sem_post (inlined)
\t           a0000 boost::interprocess::ipcdetail::semaphore_post (/opt/libfastrtps.so.2.14)
\t           a1000 eprosima::fastdds::rtps::SharedMemTransport::send (/opt/libfastrtps.so.2.14)
\t           a2000 eprosima::fastrtps::rtps::WriterHistory::add_change (/opt/libfastrtps.so.2.14)
\t           b0000 rcl_publish_serialized_message (/opt/ros/lib/librcl.so)
\t            9400 pump_deliver ({NATIVE})
{ROOT_FRAMES}
gz-native 12199
\t           c0000 __memmove_avx_unaligned_erms (/usr/lib/x86_64-linux-gnu/libc.so.6)
\t            9500 rgb_to_cdr ({NATIVE})
{ROOT_FRAMES}
ZMQbg/IO/0 12200
\t          123456 _PyEval_EvalFrameDefault ({PYTHON})

ZMQbg/IO/0 12200
\tffffffff81734c91 eventfd_write ([kernel.kallsyms])
\tffffffff816b930a vfs_write ([kernel.kallsyms])
\tffffffff816b9856 ksys_write ([kernel.kallsyms])
\tffffffff821ed511 do_syscall_64 ([kernel.kallsyms])
\t           f838f __GI___libc_write (/usr/lib/x86_64-linux-gnu/libc.so.6)
\t           5e21e [unknown] ({LIBZMQ})

"""


def test_perf_samples_fall_into_stages_parts_and_cross_cuts() -> None:
    samples = list(perf_profile.parse(PERF_SCRIPT))
    assert [(s.comm, s.tid) for s in samples] == [("gz-native", 12199)] * 3 + [
        ("ZMQbg/IO/0", 12200)
    ] * 2
    # An inlined frame takes the object of the real frame at its address, else unknown.
    assert samples[0].frames[4].library == "unknown"
    assert samples[0].frames[-4].library == NATIVE
    loop = perf_profile.Profile()
    for sample in samples[:3]:
        loop.add(sample)
    assert loop.stages == Counter(
        {
            "receive from libzmq (zmq_msg_recv)": 1,
            "publish through rcl (rmw, Fast DDS)": 1,
            "C and C++ runtime (outside the stages above)": 1,
        }
    )
    shared_memory = next(name for name, _ in perf_profile.PARTS if name.startswith("shared"))
    assert loop.parts == Counter({("publish through rcl (rmw, Fast DDS)", shared_memory): 1})
    assert loop.calls == Counter(
        {
            ("receive from libzmq (zmq_msg_recv)", "poll"): 1,
            ("publish through rcl (rmw, Fast DDS)", "futex"): 1,
        }
    )
    assert loop.cuts["in system calls"] == 2
    assert loop.cuts["waking another thread"] == 1
    assert loop.cuts["copying memory (memcpy, memmove)"] == 1
    other = perf_profile.Profile()
    other.add(samples[3])
    assert other.stages == Counter({"Python interpreter (outside the stages above)": 1})
    assert other.cuts == Counter({"the Python interpreter itself": 1})
    # A call whose handler the kernel inlined is named by the function it calls (ksys_write).
    assert perf_profile.syscall(samples[4]) == "write"
    assert perf_profile.stage(samples[4]) == "kernel: write"
    returning = perf_profile.Sample(
        "ZMQbg/IO/0",
        12200,
        tuple(
            perf_profile.Frame(symbol, "[kernel.kallsyms]")
            for symbol in ("__schedule", "schedule", "exit_to_user_mode_loop", "do_syscall_64")
        ),
    )
    assert perf_profile.syscall(returning) == "the return to user space (rescheduled there, rseq)"


def _found(us_loop: float, *, ceiling: bool = False) -> CpuMap:
    """1,000 messages in a clean window of one second: a role's CPU ms are its µs."""
    found = CpuMap(10, 0.5, ceiling=ceiling, clean=Delivered(900, 100, 1.0))
    found.roles = {
        "Gazebo -> ROS loop": RoleUse(1, us_loop / 1000, 300, 50, frozenset({"gz-native"})),
        "libzmq I/O": RoleUse(1, 0.010, 400, 5, frozenset({"ZMQbg/IO/N"})),
    }
    found.cpu_percent = 100 * (us_loop / 1000 + 0.010)
    found.syscall_window = Delivered(1800, 200, 2.0)
    found.syscalls = {"Gazebo -> ROS loop": Counter({"getpid": 4000, "poll": 2000})}
    found.names = frozenset({"gz-native", "ZMQbg/IO/0"})
    loop = perf_profile.Profile()
    loop.samples = 100
    loop.stages.update({"publish through rcl (rmw, Fast DDS)": 60, "wait for work": 40})
    found.profiles = {"Gazebo -> ROS loop": loop}
    return found


def test_a_stage_is_its_share_of_the_samples_times_the_threads_clean_cpu() -> None:
    found = _found(30.0)
    assert found.us("Gazebo -> ROS loop") == 30.0  # 30 ms over 1,000 messages
    assert found.total_us == 40.0
    assert found.per("Gazebo -> ROS loop", lambda use: use.voluntary) == 0.3
    assert found.calls("Gazebo -> ROS loop") == {"getpid": 2.0, "poll": 1.0}
    assert found.stage_us("Gazebo -> ROS loop", "publish through rcl (rmw, Fast DDS)") == 18.0
    assert found.items()[0] == (18.0, "Gazebo -> ROS loop", "publish through rcl (rmw, Fast DDS)")
    assert "the two native loops before issue 35's unification" in found.loop_kind()
    stored = numbers([found])
    assert stored["bridge10.us_per_message"] == 40.0
    assert stored["bridge10.gazebo_ros_loop.wakeups_per_message"] == 0.3
    assert stored["bridge10.gazebo_ros_loop.syscalls_per_message"] == 3.0


def test_the_biggest_item_and_the_excess_over_the_ceiling_are_named() -> None:
    bridge, ceiling = _found(30.0), _found(20.0, ceiling=True)
    lines = biggest(bridge, ceiling)
    assert lines[0].startswith(
        "- 10 robots: the biggest item is **publish through rcl (rmw, Fast DDS)** on the "
        "Gazebo -> ROS loop threads: 18.00 of 40.00 µs per message (45%), 1.5x the next."
    )
    assert "Over the ceiling (40.00 against 30.00 µs): publish through rcl" in lines[1]
    args = argparse.Namespace(seconds=1.0, syscall_seconds=2.0, profile_seconds=2.0, hz=999)
    text = section([bridge, ceiling], args, (0.5, 0.7))
    assert "**40.00 µs of CPU per delivered message**" in text
    assert "| publish through rcl (rmw, Fast DDS) | 18.00 | 12.00 | +6.00 |" in text
    assert "| **all** | **40.00** | **30.00** | **+10.00** |" in text
