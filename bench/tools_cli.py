"""Introspection tools, ours vs Debian's ROS 1, against the same ninjemys master in the same run.

Wall time (median of N runs, runs of the two implementations interleaved) of
  rostopic list, rosnode list, rosparam get /, rostopic echo -n 1 on a latched topic,
  rosservice call of a std_srvs/Trigger service,
their CPU time (user+sys from wait4: less sensitive than wall time to a loaded machine),
CPU % (steady state, from /proc/<pid>/stat between two samples after a warm-up) of
  rostopic echo and rostopic hz on a 1 kHz std_msgs/Int32 topic,
and the latency of a Tab press (``rostopic echo <Tab>`` through bash and our completion file) next to
what rosbash runs for the same Tab (``rostopic list``).

The publishers are a ninjemys node started here. Output of echo/hz goes to files, so neither tool
pays for a terminal; the number of messages echo printed shows whether it kept up.

    .venv/bin/python bench/tools_cli.py [--runs N] [--seconds S]
"""

from __future__ import annotations

import argparse
import os
import shlex
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.testing import have_ros1, ninjemys_bin, ros1_env, run_master  # noqa: E402

OURS = "ninjemys"
REAL = "ROS 1"
CLK_TCK = os.sysconf("SC_CLK_TCK")

#: the graph the tools look at: a latched topic, a Trigger service and a 1 kHz small-message topic
NODE = r"""
import sys, rospy
from std_msgs.msg import Int32, String
from std_srvs.srv import Trigger, TriggerResponse
rospy.init_node('bench_graph')
latched = rospy.Publisher('latched', String, queue_size=1, latch=True)
latched.publish('hello')
rospy.Service('trigger', Trigger, lambda req: TriggerResponse(True, 'done'))
fast = rospy.Publisher('fast', Int32, queue_size=100)
for i in range(20):
    rospy.set_param('/bench/group%d/value' % i, i)
print('ready', flush=True)
rate = rospy.Rate(1000)
i = 0
while not rospy.is_shutdown():
    fast.publish(i)
    i += 1
    rate.sleep()
"""

WALL_CASES: list[tuple[str, list[str]]] = [
    ("rostopic list", ["rostopic", "list"]),
    ("rosnode list", ["rosnode", "list"]),
    ("rosparam get /", ["rosparam", "get", "/"]),
    ("rostopic echo -n 1 /latched", ["rostopic", "echo", "-n", "1", "/latched"]),
    ("rosservice call /trigger", ["rosservice", "call", "/trigger"]),
]


def precompile() -> None:
    """Byte-compile our sources once, as ``pip install`` does (this sandbox sets PYTHONDONTWRITEBYTECODE)."""
    import compileall

    compileall.compile_dir(str(Path(__file__).resolve().parents[1] / "src"), quiet=1)


def command(impl: str, argv: list[str], uri: str) -> tuple[list[str], dict[str, str]]:
    if impl == OURS:
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        return [ninjemys_bin(argv[0]), *argv[1:]], env
    return [f"/usr/bin/{argv[0]}", *argv[1:]], ros1_env(uri)


def wall(impl: str, argv: list[str], uri: str) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the process and its children) of one run of a command."""
    cmd, env = command(impl, argv, uri)
    with tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        elapsed = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{impl} {' '.join(argv)} failed: {err.read().decode().strip()}")
    return elapsed, usage.ru_utime + usage.ru_stime


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK  # utime + stime


def steady_cpu(impl: str, argv: list[str], uri: str, warmup: float, seconds: float) -> tuple[float, str]:
    """CPU % of a long-running tool after ``warmup`` s, over ``seconds`` s; and what it printed."""
    cmd, env = command(impl, argv, uri)
    with tempfile.TemporaryFile() as out:
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            time.sleep(warmup)
            c0, t0 = cpu_seconds(proc.pid), time.perf_counter()
            time.sleep(seconds)
            c1, t1 = cpu_seconds(proc.pid), time.perf_counter()
        finally:
            os.killpg(proc.pid, signal.SIGINT)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        out.seek(0)
        text = out.read().decode("utf-8", "replace")
    return 100.0 * (c1 - c0) / (t1 - t0), text


def tab_press(uri: str) -> float:
    """Wall time of ``rostopic echo <Tab>``: bash runs our completion function, which asks the master."""
    bash_file = subprocess.run(
        [sys.executable, "-m", "ninjemys.tools.complete", "--path"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    script = (
        f"source {shlex.quote(bash_file)}\n"
        "COMP_WORDS=(rostopic echo /); COMP_CWORD=2\n"
        "s=$EPOCHREALTIME; _rostopic; e=$EPOCHREALTIME\n"
        'echo "${#COMPREPLY[@]} $s $e"\n'
    )
    env = dict(os.environ, ROS_MASTER_URI=uri, NINJEMYS_PYTHON=sys.executable)
    count, start, end = subprocess.run(
        ["bash", "--norc", "-c", script], env=env, capture_output=True, text=True, check=True
    ).stdout.split()
    if int(count) < 3:
        raise RuntimeError("completion returned too few topics")
    return float(end) - float(start)


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--runs", type=int, default=9, help="runs per command and implementation")
    parser.add_argument("--seconds", type=float, default=6.0, help="CPU sampling window of echo/hz")
    args = parser.parse_args()
    if not have_ros1():
        print("Debian's ROS 1 is not installed: nothing to compare with", file=sys.stderr)
        return 1
    precompile()
    impls = [OURS, REAL]
    home = tempfile.mkdtemp(prefix="bench_tools_home_")
    os.environ["ROS_HOME"] = home
    print(
        f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (shared; figures are noisy)"
    )
    with run_master() as uri:
        script = Path(home) / "bench_graph.py"
        script.write_text(NODE)
        node = subprocess.Popen(
            [sys.executable, str(script)],
            env=dict(os.environ, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost"),
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        try:
            assert node.stdout is not None
            if node.stdout.readline().strip() != "ready":
                raise RuntimeError("the benchmark graph node did not start")
            rows: list[tuple[str, float, float, str]] = []
            for label, argv in WALL_CASES:
                times: dict[str, list[float]] = {impl: [] for impl in impls}
                cpu: dict[str, list[float]] = {impl: [] for impl in impls}
                for impl in impls:  # one untimed run each: page cache, pyc files
                    wall(impl, argv, uri)
                for _ in range(args.runs):
                    for impl in impls:
                        elapsed, used = wall(impl, argv, uri)
                        times[impl].append(elapsed)
                        cpu[impl].append(used)
                ours, real = (statistics.median(times[i]) * 1000 for i in impls)
                rows.append((f"{label} (wall, ms)", ours, real, f"median of {args.runs}"))
                ours, real = (statistics.median(cpu[i]) * 1000 for i in impls)
                rows.append((f"{label} (CPU, ms)", ours, real, "user+sys, less sensitive to load"))
            for label, argv in [
                ("rostopic echo /fast, 1 kHz", ["rostopic", "echo", "/fast"]),
                ("rostopic hz /fast, 1 kHz", ["rostopic", "hz", "/fast"]),
            ]:
                result = {}
                for impl in impls:
                    percent, text = steady_cpu(impl, argv, uri, warmup=3.0, seconds=args.seconds)
                    extra = ""
                    if "echo" in argv:
                        extra = f"{text.count('---')} msgs"
                    else:
                        rates = [line.split()[-1] for line in text.splitlines() if "average rate" in line]
                        extra = f"last rate {rates[-1] if rates else '?'}"
                    result[impl] = (percent, extra)
                note = f"ours {result[OURS][1]}, ROS 1 {result[REAL][1]}"
                rows.append((f"{label} (CPU %)", result[OURS][0], result[REAL][0], note))
            tabs = [tab_press(uri) * 1000 for _ in range(args.runs)]
            rosbash = [wall(REAL, ["rostopic", "list"], uri)[0] * 1000 for _ in range(args.runs)]
            rows.append(
                (
                    "rostopic echo <Tab> (wall, ms)",
                    statistics.median(tabs),
                    statistics.median(rosbash),
                    "ROS 1 column: the `rostopic list` rosbash runs",
                )
            )
        finally:
            node.kill()
            node.wait()
    width = max(len(r[0]) for r in rows)
    print(f"{'figure':<{width}}  {'ninjemys':>9}  {'ROS 1':>9}  {'ratio':>6}  note")
    for label, ours, real, note in rows:
        ratio = ours / real if real else float("inf")
        print(f"{label:<{width}}  {ours:9.1f}  {real:9.1f}  {ratio:6.2f}  {note}")
    print("ratio = ninjemys / ROS 1 (target: <= 0.50 on every figure)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
