"""Processes for the introspection-tool tests: a fixed graph of ninjemys nodes plus a real rospy node,
over either our roscore or Debian's real one. Every process is killed by the fixture that started it."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ninjemys.testing import ninjemys_bin, ros1_env, run_real_roscore

#: a ninjemys node (run with our interpreter): talker on /chatter with a counter, a latched topic and
#: the std_srvs/SetBool service /set_flag. argv: name rate_hz
NINJEMYS_NODE = r"""
import sys, rospy
from std_msgs.msg import String
from std_srvs.srv import SetBool, SetBoolResponse
rospy.init_node(sys.argv[1])
rate_hz = float(sys.argv[2])
pub = rospy.Publisher('chatter', String, queue_size=1000)
latched = rospy.Publisher('status', String, queue_size=1, latch=True)
latched.publish('ready')
rospy.Service('set_flag', SetBool, lambda r: SetBoolResponse(r.data, 'flag is %s' % r.data))
print('ready', flush=True)
rate = rospy.Rate(rate_hz)
i = 0
while not rospy.is_shutdown():
    pub.publish('hello %d' % i)
    i += 1
    rate.sleep()
"""

#: a real rospy listener (run with /usr/bin/python3)
ROSPY_LISTENER = r"""
import rospy
from std_msgs.msg import String
rospy.init_node('listener')
rospy.Subscriber('chatter', String, lambda m: None)
print('ready', flush=True)
rospy.spin()
"""


def ninjemys_env(master_uri: str) -> dict[str, str]:
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = master_uri
    env["ROS_HOSTNAME"] = "localhost"
    return env


def wait_ready(proc: subprocess.Popen, what: str, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    assert proc.stdout is not None
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if line.strip() == "ready":
            return
        if not line and proc.poll() is not None:
            raise RuntimeError(f"{what} exited with {proc.returncode}")
    raise RuntimeError(f"{what} not ready within {timeout} s")


def stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.kill()
    proc.wait()


@contextmanager
def real_roscore() -> Iterator[str]:
    """Debian's roscore with its own ROS_HOME; the whole process tree is killed afterwards."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="real_roscore_") as home, run_real_roscore(home) as uri:
        yield uri


@contextmanager
def graph(master_uri: str, tmp: Path, rate_hz: float = 10.0, listener: bool = True) -> Iterator[dict]:
    """Start /talker (ninjemys) and /listener (real rospy) on ``master_uri``."""
    script = tmp / "ninjemys_node.py"
    script.write_text(NINJEMYS_NODE)
    procs = []
    try:
        talker = subprocess.Popen(
            [sys.executable, str(script), "talker", str(rate_hz)],
            env=ninjemys_env(master_uri),
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        procs.append(talker)
        wait_ready(talker, "ninjemys talker")
        if listener:
            lscript = tmp / "rospy_listener.py"
            lscript.write_text(ROSPY_LISTENER)
            proc = subprocess.Popen(
                ["/usr/bin/python3", str(lscript)],
                env=ros1_env(master_uri),
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                text=True,
            )
            procs.append(proc)
            wait_ready(proc, "rospy listener")
        yield {"talker": talker}
    finally:
        for proc in procs:
            stop(proc)


def run_tool(
    tool: str, args: list[str], master_uri: str, real: bool, timeout: float = 20.0, **kw
) -> subprocess.CompletedProcess:
    """Run ours (venv) or Debian's tool by full path against ``master_uri``."""
    if real:
        cmd, env = [f"/usr/bin/{tool}", *args], ros1_env(master_uri)
    else:
        cmd, env = [ninjemys_bin(tool), *args], ninjemys_env(master_uri)
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, **kw)


_MASKS = [
    (re.compile(r"Pid: \d+"), "Pid: PID"),
    (re.compile(r"\(\d+ - [\w.]+:\d+\) \[\d+\]"), "(PORT - ADDR) [FD]"),
    (re.compile(r"time=[\d.]+ms"), "time=Tms"),
    (re.compile(r"average: [\d.]+ms"), "average: Tms"),
]


def normalize(text: str) -> str:
    for pattern, repl in _MASKS:
        text = pattern.sub(repl, text)
    return text
