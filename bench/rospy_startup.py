"""`import rospy; rospy.init_node(...)` process wall time and a seed-style talker's CPU, ninjemys vs Debian's rospy.

    .venv/bin/python bench/rospy_startup.py [--runs 9] [--talker-seconds 5]

Both implementations register with the same master (Debian's rosmaster, so neither side is favoured)
and run as fresh processes; figures are medians (the process wall also as the minimum: on a shared
machine the minimum is the least disturbed run). Besides the bare ``init_node`` process, it times the
phases of the process (interpreter start, import rospy, init_node, exit: atexit, unregistering and
interpreter teardown, from the parent's clock and the child's; both are CLOCK_MONOTONIC) and measures the CPU seconds the seeds' talker loop
(loginfo + publish + Rate.sleep) burns per wall second at 10 Hz and 100 Hz, and the CPU cost of one
``rospy.loginfo`` (console, log file and /rosout).
"""

from __future__ import annotations

import argparse
import os
import resource
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import xmlrpc.client
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.testing import ROS1_PYTHON, free_port, have_ros1, ros1_env  # noqa: E402

OURS, REAL = "ninjemys", "rospy"

BARE = "import rospy; rospy.init_node('bench_init', anonymous=True)"

PHASES = """
import time
t0 = time.perf_counter()
import rospy
t1 = time.perf_counter()
rospy.init_node('bench_phases', anonymous=True)
t2 = time.perf_counter()
import sys
sys.stdout.write('%f %f %f\\n' % (t0, t1, t2))
sys.stdout.flush()
"""

TALKER = """
import sys, rospy
from std_msgs.msg import String
pub = rospy.Publisher('chatter', String, queue_size=10)
rospy.init_node('bench_talker', anonymous=True)
rate = rospy.Rate(float(sys.argv[1]))
try:
    while not rospy.is_shutdown():
        hello_str = "hello world %s" % rospy.get_time()
        rospy.loginfo(hello_str)
        pub.publish(hello_str)
        rate.sleep()
except rospy.ROSInterruptException:
    pass
"""


def _env(impl: str, master: str, home: str) -> dict[str, str]:
    if impl == REAL:
        return ros1_env(master, ROS_HOME=home)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(ROS_MASTER_URI=master, ROS_HOME=home, ROS_HOSTNAME="localhost")
    return env


def _python(impl: str) -> str:
    return ROS1_PYTHON if impl == REAL else sys.executable


def bare(impl: str, master: str, home: str, runs: int, code: str = BARE) -> tuple[float, float, float]:
    """Median wall time, minimum wall time and median CPU time (user + system) of a fresh process."""
    walls, cpus = [], []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(
            [_python(impl), "-c", code], env=_env(impl, master, home), check=True, capture_output=True
        )
        walls.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return statistics.median(walls), min(walls), statistics.median(cpus)


def phases(impl: str, master: str, home: str, runs: int) -> tuple[float, float, float, float]:
    """Medians of: interpreter start-up, import rospy, init_node, exit (init_node return -> reaped)."""
    starts, imports, inits, exits = [], [], [], []
    for _ in range(runs):
        spawned = time.perf_counter()
        out = subprocess.run(
            [_python(impl), "-c", PHASES],
            env=_env(impl, master, home),
            check=True,
            capture_output=True,
            text=True,
        ).stdout.split()
        ended = time.perf_counter()
        t0, t1, t2 = (float(x) for x in out[-3:])
        starts.append(t0 - spawned)
        imports.append(t1 - t0)
        inits.append(t2 - t1)
        exits.append(ended - t2)
    return tuple(statistics.median(v) for v in (starts, imports, inits, exits))  # type: ignore[return-value]


def talker_cpu(impl: str, master: str, home: str, hz: float, seconds: float) -> float:
    """CPU seconds per wall second of a seed-style talker (after a 1 s warm-up)."""
    proc = subprocess.Popen(
        [_python(impl), "-c", TALKER, str(hz)],
        env=_env(impl, master, home),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        time.sleep(1.0)
        before = _cpu(proc.pid)
        start = time.perf_counter()
        time.sleep(seconds)
        used = _cpu(proc.pid) - before
        return used / (time.perf_counter() - start)
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


LOGCOST = """
import sys, time, rospy
rospy.init_node('bench_log', anonymous=True)
n = 2000
t = time.thread_time()
for i in range(n):
    rospy.loginfo("hello world %s" % rospy.get_time())
sys.stderr.write("%f\\n" % ((time.thread_time() - t) / n))
"""


def loginfo_cost(impl: str, master: str, home: str) -> float:
    done = subprocess.run(
        [_python(impl), "-c", LOGCOST],
        env=_env(impl, master, home),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        check=True,
    )
    return float(done.stderr.strip().splitlines()[-1])


def _cpu(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    ticks = os.sysconf("SC_CLK_TCK")
    return (int(fields[11]) + int(fields[12])) / ticks


def _ratio(ours: float, real: float) -> str:
    return f"{ours / real:.2f}x" if real else "n/a"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--talker-seconds", type=float, default=5.0)
    args = parser.parse_args()
    if not have_ros1():
        sys.exit("ERROR: this benchmark compares against Debian's ROS 1 (/usr/bin/python3 with rospy)")
    port = free_port()
    master = f"http://localhost:{port}/"
    with tempfile.TemporaryDirectory() as home:
        core = subprocess.Popen(
            ["/usr/bin/rosmaster", "--core", "-p", str(port)],
            env=ros1_env(master, ROS_HOME=home),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            deadline = time.monotonic() + 20
            while True:
                try:
                    xmlrpc.client.ServerProxy(master).getPid("/bench")
                    break
                except OSError:
                    if time.monotonic() > deadline:
                        sys.exit("ERROR: rosmaster did not start")
                    time.sleep(0.05)
            for impl in (OURS, REAL):  # warm-up: byte-code caches, page cache
                bare(impl, master, home, 1)
            rows = []
            runs = {impl: bare(impl, master, home, args.runs) for impl in (OURS, REAL)}
            rows.append(("import rospy; init_node process wall (s)", runs[OURS][0], runs[REAL][0]))
            rows.append(("  same, minimum of the runs (s)", runs[OURS][1], runs[REAL][1]))
            rows.append(("import rospy; init_node process CPU (s)", runs[OURS][2], runs[REAL][2]))
            ph = {impl: phases(impl, master, home, args.runs) for impl in (OURS, REAL)}
            rows.append(("  of which interpreter start (s)", ph[OURS][0], ph[REAL][0]))
            rows.append(("  of which import rospy (s)", ph[OURS][1], ph[REAL][1]))
            rows.append(("  of which init_node (s)", ph[OURS][2], ph[REAL][2]))
            rows.append(("  of which exit (s)", ph[OURS][3], ph[REAL][3]))
            empty = {impl: bare(impl, master, home, args.runs, "pass") for impl in (OURS, REAL)}
            rows.append(("bare interpreter, python -c pass (s)", empty[OURS][0], empty[REAL][0]))
            cost = {impl: loginfo_cost(impl, master, home) * 1e6 for impl in (OURS, REAL)}
            rows.append(("one rospy.loginfo, CPU (us)", cost[OURS], cost[REAL]))
            for hz in (10.0, 100.0):
                cpu = {impl: talker_cpu(impl, master, home, hz, args.talker_seconds) for impl in (OURS, REAL)}
                rows.append((f"CPU of the seed talker at {hz:.0f} Hz (cpu s / s)", cpu[OURS], cpu[REAL]))
        finally:
            core.kill()
            core.wait()
    print(
        f"rospy startup and talker CPU, median of {args.runs} runs (machine load: {os.getloadavg()[0]:.1f})"
    )
    print(f"{'figure':<44}{OURS:>10}{REAL:>10}   ratio")
    for label, ours, real in rows:
        print(f"{label:<44}{ours:>10.3f}{real:>10.3f}   {_ratio(ours, real)}")


if __name__ == "__main__":
    main()
