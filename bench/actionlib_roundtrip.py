"""actionlib goal -> result round trips per second with trivial goals: ninjemys vs Debian's actionlib.

Run: ``.venv/bin/python bench/actionlib_roundtrip.py [goals]`` (default 300). Target: at least 3x
Debian's round trips per second.

The same ROS 1 program (rospy + actionlib: a SimpleActionServer that succeeds at once with a + b,
and a SimpleActionClient that sends goal after goal, each after the previous result) runs under our
interpreter (ninjemys' rospy and actionlib facades) and under /usr/bin/python3 (Debian's real
rospy and actionlib), on one master. The mixed pairs are printed too. Each pair gets a fresh
action name, so no server inherits another's status list; ROS 1 keeps finished goals in it for
5 s, so the rate of a long run is lower than that of a short one for every implementation, and
all pairs run the same count.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

from ninjemys.testing import ROS1_PYTHON, have_ros1, ros1_env, run_master

PROGRAM = """
import sys, time
import rospy, actionlib
from actionlib.msg import TwoIntsAction, TwoIntsGoal, TwoIntsResult

role, ns = sys.argv[1], sys.argv[2]
rospy.init_node(role, anonymous=True)
if role == "server":
    def execute(goal):
        server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))
    server = actionlib.SimpleActionServer(ns, TwoIntsAction, execute, auto_start=False)
    server.start()
    print("READY", flush=True)
    rospy.spin()
else:
    count = int(sys.argv[3])
    client = actionlib.SimpleActionClient(ns, TwoIntsAction)
    client.wait_for_server()
    client.send_goal(TwoIntsGoal(a=0, b=0))  # warm-up: connections, first messages
    client.wait_for_result()
    start = time.perf_counter()
    for i in range(count):
        client.send_goal(TwoIntsGoal(a=i, b=1))
        if not client.wait_for_result(rospy.Duration(10)) or client.get_result().sum != i + 1:
            print("LOST", i, flush=True)
    elapsed = time.perf_counter() - start
    print("RATE %.1f" % (count / elapsed), flush=True)
"""


def _python(impl: str) -> tuple[str, dict[str, str]]:
    return (sys.executable, dict(os.environ)) if impl == "ours" else (ROS1_PYTHON, {})


def pair(uri: str, script: Path, server_impl: str, client_impl: str, ns: str, count: int, home: str) -> float:
    exe_s, env_s = _python(server_impl)
    exe_c, env_c = _python(client_impl)
    env_s = (
        {**env_s, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "localhost", "ROS_HOME": home}
        if env_s
        else ros1_env(uri, ROS_HOME=home)
    )
    env_c = (
        {**env_c, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "localhost", "ROS_HOME": home}
        if env_c
        else ros1_env(uri, ROS_HOME=home)
    )
    server = subprocess.Popen(
        [exe_s, str(script), "server", ns],
        env=env_s,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert server.stdout is not None and server.stdout.readline().strip() == "READY"
        done = subprocess.run(
            [exe_c, str(script), "client", ns, str(count)],
            env=env_c,
            capture_output=True,
            text=True,
            timeout=600,
        )
        lost = [line for line in done.stdout.splitlines() if line.startswith("LOST")]
        rates = [float(line.split()[1]) for line in done.stdout.splitlines() if line.startswith("RATE")]
        if not rates:
            raise RuntimeError(f"client failed: {done.stderr[-2000:]}")
        if lost:
            print(f"  ({len(lost)} goals without a result in 10 s)")
        return rates[0]
    finally:
        server.kill()
        server.wait()


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 300
    if not have_ros1():
        sys.exit("needs Debian's ROS 1 (python3-actionlib)")
    load = os.getloadavg()
    print(f"actionlib round trips, {count} trivial goals per pair; load average {load[0]:.2f} {load[1]:.2f}")
    with tempfile.TemporaryDirectory() as tmp, run_master() as uri:
        script = Path(tmp) / "roundtrip_program.py"
        script.write_text(PROGRAM)
        results = {}
        for i, (server_impl, client_impl) in enumerate(
            (("ours", "ours"), ("debian", "debian"), ("ours", "debian"), ("debian", "ours"))
        ):
            rate = pair(uri, script, server_impl, client_impl, f"bench_{i}", count, tmp)
            results[(server_impl, client_impl)] = rate
            print(f"server {server_impl:7s} client {client_impl:7s} {rate:9.1f} round trips/s")
        ours, theirs = results[("ours", "ours")], results[("debian", "debian")]
        print(f"ratio ours/debian (both ends): {ours / theirs:.1f}x (target >= 3x)")


if __name__ == "__main__":
    main()
