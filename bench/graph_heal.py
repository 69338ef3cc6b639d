"""Graph-heal time: after a master restart (ours vs Debian's ROS 1, side by side), and over the soak.

    .venv/bin/python bench/graph_heal.py [--restarts 5] [--soak 120] [--cut-rounds 20]

Part 1, both implementations in one run: a master, a talker (20 Hz); the master is SIGKILLed and
restarted on the same port; then a *late* listener starts. It can only hear the talker if the new
master knows it again: the time from the new master answering to the late listener's first message
is the heal time. ROS 1 nodes never re-register, so real rospy's late listener hears nothing (the
figure is "none within the wait"). Part 2 runs the soak (tests/soak/soak.py: 50 nodes, SIGKILLs,
two master restarts, a cut link in network namespaces where root allows) and prints its heal p50/p95.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "tests"))

from ninjemys import testing  # noqa: E402

NODE = str(ROOT / "tests" / "multihost" / "node_proc.py")  # our talker / listener
RospyTalker = """
import rospy, std_msgs.msg as m
rospy.init_node('talker_r')
pub = rospy.Publisher('/heal', m.String, queue_size=10)
print('ready', flush=True)
r = rospy.Rate(20)
i = 0
while not rospy.is_shutdown():
    pub.publish(m.String('r %d' % i)); i += 1; r.sleep()
"""
RospyListener = """
import rospy, time, std_msgs.msg as m
rospy.init_node('late_listener', anonymous=True)
rospy.Subscriber('/heal', m.String, lambda msg: print('got %s %.3f' % (msg.data, time.time()), flush=True))
print('ready', flush=True)
rospy.spin()
"""


class Master:
    def __init__(self, impl: str, port: int, home: str) -> None:
        self.impl, self.port, self.home = impl, port, home
        self.uri = f"http://localhost:{port}/"
        self.proc: testing.NodeProcess | None = None

    def env(self) -> dict[str, str]:
        if self.impl == "ros1":
            return testing.ros1_env(self.uri, ROS_HOME=self.home)
        env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
        return env | {"ROS_MASTER_URI": self.uri, "ROS_HOSTNAME": "localhost", "ROS_HOME": self.home,
                      "PYTHONUNBUFFERED": "1"}  # fmt: skip

    def start(self) -> float:
        from ninjemys.net import auth

        cmd = (
            ["/usr/bin/rosmaster", "--core", "-p", str(self.port)]
            if self.impl == "ros1"
            else [testing.ninjemys_bin("roscore"), "-p", str(self.port)]
        )
        self.proc = testing.NodeProcess(cmd, env=self.env())
        while True:
            try:
                auth.server_proxy(self.uri).getPid("/bench")
                return time.time()
            except OSError:
                time.sleep(0.01)

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()

    def node(self, role: str) -> testing.NodeProcess:
        if self.impl == "ros1":
            script = RospyTalker if role == "talker" else RospyListener
            return testing.NodeProcess([testing.ROS1_PYTHON, "-c", script], env=self.env())
        args = [
            sys.executable,
            NODE,
            role,
            "/heal",
            "o" if role == "talker" else f"late{time.monotonic_ns()}",
        ]
        return testing.NodeProcess(args, env=self.env())


def restart_heal(impl: str, restarts: int, wait: float) -> list[float | None]:
    """Heal seconds after each restart (None: the late listener heard nothing within ``wait``)."""
    out: list[float | None] = []
    with tempfile.TemporaryDirectory(prefix="bench_heal_") as home:
        master = Master(impl, testing.free_port(), home)
        master.start()
        talker = master.node("talker")
        try:
            talker.wait_for("^ready", timeout=30)
            first = master.node("listener")
            first.wait_for("^got ", timeout=30)
            first.kill()
            for _ in range(restarts):
                master.kill()
                time.sleep(1.0)
                back = master.start()
                late = master.node("listener")
                try:
                    line = late.wait_for("^got ", timeout=wait)
                    out.append(float(line.string.split()[-1]) - back)
                except testing.WaitTimeout:
                    out.append(None)
                finally:
                    late.kill()
        finally:
            talker.kill()
            master.kill()
    return out


def describe(values: list[float | None], wait: float) -> str:
    healed = [v for v in values if v is not None]
    never = len(values) - len(healed)
    text = f"p50 {statistics.median(healed):.2f} s, max {max(healed):.2f} s" if healed else ""
    if never:
        text += f"{'; ' if text else ''}{never} of {len(values)} never healed (waited {wait:g} s)"
    return text


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--restarts", type=int, default=5)
    parser.add_argument("--wait", type=float, default=15.0, help="seconds a late listener waits")
    parser.add_argument("--soak", type=float, default=120.0, help="seconds of soak faults (0: skip)")
    parser.add_argument("--cut-rounds", type=int, default=20)
    opts = parser.parse_args()
    print(f"graph heal after a master restart, a late listener (load {os.getloadavg()[0]:.1f})")
    ours = restart_heal("ours", opts.restarts, opts.wait)
    print(f"  ninjemys: {describe(ours, opts.wait)}")
    if testing.have_ros1():
        real = restart_heal("ros1", opts.restarts, opts.wait)
        print(f"  ROS 1 (rosmaster + rospy): {describe(real, opts.wait)}")
    if opts.soak:
        from soak.soak import cut_link_heals, format_report, run_soak, summarize

        report = run_soak(duration=opts.soak, rate=10.0)
        if opts.cut_rounds:
            cut = cut_link_heals(opts.cut_rounds)
            if isinstance(cut, str):
                report["cut_link_skipped"] = cut
            else:
                report["heal"]["cut_link"] = summarize(cut)
        print(format_report(report))


if __name__ == "__main__":
    main()
