"""CPU of robot_state_publisher at 50 Hz joint states for a 20-joint robot: ninjemys vs Debian's C++.

Run: ``.venv/bin/python bench/robot_state_publisher.py`` (``--seconds N`` per round, default 20;
``--rounds N``, default 1; ``--still``: the robot at rest, the same positions in every message (a
joint_state_publisher with nothing moving), only the stamps new; ``--floor`` adds two stripped
copies of ours that show where the floor is: ``receive`` takes each JointState and does nothing
with it, ``no_fk`` does everything but compute and serialise the transforms, publishing the first
message it made again and again; ``--compare SRC`` adds ours from another tree, two copies of each
side interleaved, and prints their CPU ratio; ``--threads``: per thread of ours and Debian's, CPU
per received message and wake-ups (voluntary context switches) per second, to see where a message's
CPU goes and which threads wake without work).

One master (ours), one description (a chain of 20 revolute joints with odd origins and axes, and
two fixed joints), one JointState stream at 50 Hz from this process with a new stamp every message.
Both state publishers run at once, ours and Debian's ``/usr/lib/robot_state_publisher``, each on
its own remapped /tf, and each one's CPU time (user + system from /proc) is taken over the same
window; the transforms each published in that window are counted so a silent node cannot win.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "src"))

JOINTS = 20
DEBIAN = Path("/usr/lib/robot_state_publisher/robot_state_publisher")


def description() -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(JOINTS + 3))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0.{i % 7} 0.1 0.2" rpy="0.{i % 5} -0.3 1.{i % 3}"/><axis xyz="0 {i % 2} 1"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        for i in range(JOINTS)
    )
    fixed = "".join(
        f'<joint name="f{k}" type="fixed"><parent link="l{JOINTS}"/><child link="l{JOINTS + 1 + k}"/></joint>'
        for k in range(2)
    )
    return f'<robot name="bench">{links}{joints}{fixed}</robot>'


def cpu_seconds(pid: int) -> float:
    """CPU time of all of ``pid``'s threads: the scheduler's own count in nanoseconds
    (``/proc/PID/task/*/schedstat``) where the kernel keeps it, else user + system time in clock ticks.
    Ticks are too coarse here: 0.7 % of a core for 15 s is ~10 ticks of 10 ms, sampled, so a round's
    figure moved by +-30 % from sampling alone."""
    total, tasks = 0, Path(f"/proc/{pid}/task")
    try:
        for task in tasks.iterdir():
            total += int((task / "schedstat").read_text().split()[0])
        return total / 1e9
    except (OSError, ValueError, IndexError):
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def thread_stats(pid: int) -> dict[int, tuple[float, int]]:
    """Per thread of ``pid``: (CPU seconds from schedstat, voluntary context switches so far)."""
    stats: dict[int, tuple[float, int]] = {}
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            cpu = int((task / "schedstat").read_text().split()[0]) / 1e9
            status = (task / "status").read_text()
        except (OSError, ValueError, IndexError):
            continue
        switches = next(int(line.split()[1]) for line in status.splitlines() if line.startswith("voluntary"))
        stats[int(task.name)] = (cpu, switches)
    return stats


def print_threads(
    name: str,
    before: dict[int, tuple[float, int]],
    after: dict[int, tuple[float, int]],
    wall: float,
    received: int,
) -> None:
    """The --threads lines of one process: the threads that ran in the window, busiest first."""
    rows = []
    for tid, (cpu, switches) in after.items():
        cpu0, switches0 = before.get(tid, (0.0, 0))
        rows.append((cpu - cpu0, (switches - switches0) / wall, tid))
    rows.sort(reverse=True)
    for cpu, rate, tid in rows:
        if cpu > 0 or rate > 0:
            per = f"{1e6 * cpu / received:6.1f} us/msg" if received else ""
            print(f"    {name:7s} thread {tid}: {per}, {rate:6.1f} wake-ups/s")


#: Python run by the --floor variants before our node's main
FLOOR_PATCHES = {
    "receive": "import ninjemys.robot.state_publisher as m; m.StatePublisher.on_raw = lambda self, raw: None",
    "no_fk": (
        "import ninjemys.robot.tf_plan as m; init = m.TfPlan.__init__\n"
        "def once(self, *args, **kwargs):\n"
        "    init(self, *args, **kwargs); full, made = self.message, []\n"
        "    self.message = lambda p, st: made[0] if made else made.append(full(p, st)) or made[0]\n"
        "m.TfPlan.__init__ = once"
    ),
}


FLOOR_MAIN = "import sys\nfrom ninjemys.robot.state_publisher import main\nsys.exit(main(sys.argv[1:]))"


def floor_command(name: str) -> list[str]:
    code = f"{FLOOR_PATCHES[name]}\n{FLOOR_MAIN}"
    return [sys.executable, "-c", code, f"/tf:=/tf_{name}", f"__name:=rsp_{name}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--floor", action="store_true", help="add the receive-only and no-FK copies of ours")
    parser.add_argument(
        "--still",
        action="store_true",
        help="the robot at rest: the same positions in every message, only the stamps change",
    )
    parser.add_argument("--threads", action="store_true", help="per-thread CPU per message and wake-ups")
    parser.add_argument(
        "--compare",
        metavar="SRC",
        help="add ours as found in another source tree (e.g. a git archive of main)",
    )
    opts = parser.parse_args()
    from ninjemys import testing
    from ninjemys.idl.loader import get_message_class
    from ninjemys.node import Node
    from ninjemys.rostime import Time

    home = tempfile.mkdtemp(prefix="bench_rsp_")
    env = dict(os.environ, ROS_HOME=home, ROS_LOG_DIR=home)
    with testing.run_master(env=env) as uri:
        env.update(ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        node = Node("rsp_bench", master_uri=uri)
        node.set_param("/robot_description", description())
        TFMessage, JointState = (
            get_message_class("tf2_msgs/TFMessage"),
            get_message_class("sensor_msgs/JointState"),
        )
        counts: dict[str, int] = {}
        lock = threading.Lock()

        def counter(name: str):  # noqa: ANN202
            def count(msg) -> None:  # noqa: ANN001
                with lock:
                    counts[name] += len(msg.transforms)

            return count

        commands = {
            "ours": [
                sys.executable,
                "-m",
                "ninjemys.packages.run_shipped",
                "robot_state_publisher",
                "robot_state_publisher",
                "/tf:=/tf_ours",
                "__name:=rsp_ours",
            ],
        }
        if DEBIAN.exists():
            commands["debian"] = [str(DEBIAN), "/tf:=/tf_debian", "__name:=rsp_debian"]
        if opts.floor:
            commands.update({name: floor_command(name) for name in FLOOR_PATCHES})
        if opts.compare:
            # two copies of each side, started alike and interleaved: where the scheduler puts a
            # process moves its CPU by up to +-10 % (the same tree twice differed that much)
            here = str(Path(__file__).resolve().parent.parent / "src")
            for name, tree in (("base", opts.compare), ("ours2", here), ("base2", opts.compare)):
                code = f"import sys; sys.path.insert(0, {tree!r}); {FLOOR_MAIN}"
                commands[name] = [sys.executable, "-c", code, f"/tf:=/tf_{name}", f"__name:=rsp_{name}"]
        counts.update(dict.fromkeys(commands, 0))
        for name in commands:
            node.subscriber(f"/tf_{name}", TFMessage, counter(name), queue_size=1000)
        pub = node.publisher("/joint_states", JointState, queue_size=100)
        procs = {
            name: subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for name, argv in commands.items()
        }
        try:
            while pub.get_num_connections() < len(procs):
                time.sleep(0.05)
            time.sleep(1.0)
            names = [f"j{i}" for i in range(JOINTS)]
            period, k = 1.0 / 50.0, 0
            ratios = []
            totals = dict.fromkeys(commands, 0.0)
            for round_ in range(opts.rounds):
                start_cpu = {name: cpu_seconds(p.pid) for name, p in procs.items()}
                start_threads = (
                    {name: thread_stats(p.pid) for name, p in procs.items()} if opts.threads else {}
                )
                sent_before = k
                with lock:
                    start_counts = dict(counts)
                start = time.monotonic()
                next_t = start
                while time.monotonic() - start < opts.seconds:
                    stamp = time.time()
                    moved = 0.0 if opts.still else 0.01 * k
                    msg = JointState(name=names, position=[moved + 0.1 * i for i in range(JOINTS)])
                    msg.header.stamp = Time.from_sec(stamp)
                    pub.publish(msg)
                    k += 1
                    next_t += period
                    time.sleep(max(0.0, next_t - time.monotonic()))
                wall = time.monotonic() - start
                time.sleep(0.5)
                cpu = {name: cpu_seconds(p.pid) - start_cpu[name] for name, p in procs.items()}
                end_threads = {name: thread_stats(p.pid) for name, p in procs.items()} if opts.threads else {}
                with lock:
                    sent = {name: counts[name] - start_counts[name] for name in procs}
                print(
                    f"round {round_ + 1}: robot_state_publisher, {JOINTS} joints at 50 Hz for {wall:.0f} s "
                    f"(load {os.getloadavg()[0]:.1f}):"
                )
                for name in procs:
                    versus = f", {cpu[name] / cpu['debian']:.2f}x debian" if cpu.get("debian") else ""
                    print(
                        f"  {name:7s} CPU {100 * cpu[name] / wall:5.2f} % of a core, "
                        f"{sent[name]} transforms published{versus}"
                    )
                for name in end_threads:
                    print_threads(name, start_threads[name], end_threads[name], wall, k - sent_before)
                for name in procs:
                    totals[name] += cpu[name]
                if "debian" in cpu and cpu["debian"] > 0:
                    ratios.append(cpu["ours"] / cpu["debian"])
                    print(f"  ratio ours/debian: {ratios[-1]:.2f}")
                time.sleep(0.5)
            if opts.compare:
                ours, base = totals["ours"] + totals["ours2"], totals["base"] + totals["base2"]
                print(f"A/B over {opts.rounds} rounds: (ours + ours2) / (base + base2) = {ours / base:.3f}")
            if len(ratios) > 1:
                ratios.sort()
                print(
                    f"ratio ours/debian over {len(ratios)} rounds: median {ratios[len(ratios) // 2]:.2f}, "
                    f"range {ratios[0]:.2f}-{ratios[-1]:.2f}"
                )
        finally:
            for p in procs.values():
                p.terminate()
            for p in procs.values():
                p.wait(10)
            node.shutdown("bench done")


if __name__ == "__main__":
    main()
