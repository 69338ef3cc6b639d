"""Shared helpers of the master benchmarks: start ninjemys' or Debian's roscore, poll it, stop it."""

from __future__ import annotations

import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.errors import MasterError  # noqa: E402
from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.testing import free_port, have_ros1, ninjemys_bin, ros1_env  # noqa: E402

OURS = "ninjemys"
_HOME = tempfile.TemporaryDirectory(prefix="bench_ros_home_")  # logs of every roscore of this run


def precompile() -> None:
    """Byte-compile our sources once, as ``pip install`` does (this sandbox sets PYTHONDONTWRITEBYTECODE)."""
    import compileall

    compileall.compile_dir(str(Path(__file__).resolve().parents[1] / "src" / "ninjemys"), quiet=1)


REAL = "ROS 1"


@dataclass
class Core:
    """A running roscore (either implementation)."""

    impl: str
    proc: subprocess.Popen[bytes]
    uri: str
    started: float  # time.perf_counter() just before Popen

    def stop(self) -> float:
        """Ctrl-C as a terminal sends it (SIGINT to the process group); seconds until roscore has exited."""
        t0 = time.perf_counter()
        os.killpg(self.proc.pid, signal.SIGINT)
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.kill()
            return float("inf")
        return time.perf_counter() - t0

    def kill(self) -> None:
        """SIGKILL roscore and every descendant (roslaunch puts rosmaster/rosout in their own sessions)."""
        for pid in [*_descendants(self.proc.pid), self.proc.pid]:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.proc.wait()


def _descendants(root: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [root]
    while todo:
        for child in children.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out


def start_core(impl: str, home: str | None = None) -> Core:
    port = free_port()
    uri = f"http://localhost:{port}/"
    home = home or _HOME.name
    if impl == OURS:
        env = dict(os.environ, ROS_HOME=home, ROS_MASTER_URI=uri, ROS_HOSTNAME="localhost")
        cmd = [ninjemys_bin("roscore"), "-p", str(port)]
    else:
        env = ros1_env(uri, ROS_HOME=home)
        cmd = ["/usr/bin/roscore", "-p", str(port)]
    started = time.perf_counter()
    proc = subprocess.Popen(
        cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    return Core(impl, proc, uri, started)


def wait_ready(core: Core, timeout: float = 60.0) -> float:
    """Seconds from launch to the first successful getSystemState."""
    client = MasterClient(core.uri, "/bench", timeout=5)
    deadline = time.perf_counter() + timeout
    while True:
        try:
            client.get_system_state()
            return time.perf_counter() - core.started
        except MasterError:
            if time.perf_counter() > deadline or core.proc.poll() is not None:
                raise RuntimeError(f"{core.impl} roscore never became ready") from None
            time.sleep(0.001)


def wait_rosout(core: Core, timeout: float = 60.0) -> float:
    """Seconds from launch until the /rosout node subscribes /rosout and publishes /rosout_agg."""
    client = MasterClient(core.uri, "/bench", timeout=5)
    deadline = time.perf_counter() + timeout
    while True:
        try:
            pubs, subs, _ = client.get_system_state()
            if any(t == "/rosout" and "/rosout" in n for t, n in subs) and any(
                t == "/rosout_agg" and "/rosout" in n for t, n in pubs
            ):
                return time.perf_counter() - core.started
        except MasterError:
            pass
        if time.perf_counter() > deadline or core.proc.poll() is not None:
            raise RuntimeError(f"{core.impl} rosout never came up")
        time.sleep(0.002)


def median(values: list[float]) -> float:
    return statistics.median(values)


def ratio(ours: float, theirs: float) -> str:
    """'3.9x faster' style comparison (how many times less time we take)."""
    if ours <= 0:
        return "inf"
    r = theirs / ours
    return f"{r:.1f}x faster" if r >= 1 else f"{1 / r:.1f}x slower"


def require_ros1() -> None:
    precompile()
    if not have_ros1():
        sys.exit("Debian's ROS 1 is not installed: nothing to compare against")


__all__ = [
    "OURS",
    "REAL",
    "Core",
    "free_port",
    "median",
    "ratio",
    "require_ros1",
    "socket",
    "start_core",
    "wait_ready",
    "wait_rosout",
]
