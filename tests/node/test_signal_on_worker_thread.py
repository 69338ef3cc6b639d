"""Ctrl-C that the kernel hands to a worker thread still stops the process.

A process-directed signal goes to any thread that does not block it; CPython runs the handler only
on the main thread. These tests aim SIGINT at a non-main thread (``tgkill``) of a process whose main
thread is blocked (``rospy.spin``, a long ``rospy.sleep``, a page tool serving) and check it exits.
Before ``ninjemys.interrupt`` the main thread slept through it for good.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ninjemys.testing import ninjemys_bin, run_master

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="tgkill and /proc are Linux's")


def _tgkill_worker(pid: int, sig: int) -> int:
    """Send ``sig`` to one thread of ``pid`` that is not its main thread; the thread id used."""
    deadline = time.monotonic() + 10
    while True:
        tids = sorted(int(t) for t in os.listdir(f"/proc/{pid}/task") if int(t) != pid)
        if tids or time.monotonic() > deadline:
            break
        time.sleep(0.05)
    assert tids, "the process has no thread besides its main one"
    libc = ctypes.CDLL(None, use_errno=True)
    assert libc.tgkill(pid, tids[-1], sig) == 0, os.strerror(ctypes.get_errno())
    return tids[-1]


def _started(argv: list[str], uri: str, ready: str) -> subprocess.Popen[str]:
    proc = subprocess.Popen(
        argv,
        env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    assert proc.stdout is not None
    line = proc.stdout.readline()
    assert ready in line, line
    return proc


def _stops_on_worker_sigint(proc: subprocess.Popen[str]) -> int:
    try:
        _tgkill_worker(proc.pid, signal.SIGINT)
        return proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


NODE = """
import sys, rospy
rospy.init_node("sleeper")
print("ready", flush=True)
if sys.argv[1] == "spin":
    rospy.spin()
else:
    try:
        rospy.sleep(60)
    except rospy.ROSInterruptException:
        pass
"""


@pytest.mark.parametrize("how", ["spin", "sleep"])
def test_rospy_node_blocked_on_its_main_thread_stops(how: str, tmp_path: Path) -> None:
    script = tmp_path / "node.py"
    script.write_text(NODE)
    with run_master() as uri:
        proc = _started([sys.executable, str(script), how], uri, "ready")
        assert _stops_on_worker_sigint(proc) == 0


@pytest.mark.parametrize("tool", ["rqt_graph", "rviz", "rqt_plot"])
def test_page_tool_serving_stops(tool: str) -> None:
    with run_master() as uri:
        proc = _started([ninjemys_bin(tool), "--no-browser"], uri, "http://")
        assert _stops_on_worker_sigint(proc) == 0
