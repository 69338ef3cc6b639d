"""Shared helpers of the node benchmarks: one master, role processes of either implementation, pinned.

Both implementations run the same rospy-API code (bench/node_roles.py): ninjemys under the project's
venv interpreter, real rospy under Debian's /usr/bin/python3. The data path never touches the master,
so one Debian ``rosmaster --core`` (or our roscore when ROS 1 is absent) serves every run.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.testing import ROS1_PYTHON, free_port, have_ros1, ninjemys_bin, ros1_env  # noqa: E402

ROLES = str(Path(__file__).resolve().parent / "node_roles.py")
OURS = "ninjemys"
REAL = "rospy"
CPP = "roscpp"
IMPLS = [OURS, REAL] if have_ros1() else [OURS]


def cpp_program(name: str, source: str) -> str | None:
    """Build a roscpp reference program once (cached by the hash of its source under the temp dir)
    against Debian's libroscpp-dev; its path, or None when there is no g++ or roscpp. Every C++
    reference of the node benchmarks (node_roscpp.py, node_shm_roscpp.py) is built here."""
    if shutil.which("g++") is None or not Path("/usr/include/ros/ros.h").exists():
        return None
    digest = hashlib.sha256(source.encode()).hexdigest()[:16]
    cache = Path(tempfile.gettempdir()) / f"ninjemys-bench-{name}-{digest}"
    out = cache / "roles"
    if out.exists():
        return str(out)
    cache.mkdir(parents=True, exist_ok=True)
    src = cache / "roles.cpp"
    src.write_text(source)
    tmp = cache / f"roles-{os.getpid()}.tmp"
    libs = [
        "-lroscpp",
        "-lrosconsole",
        "-lroscpp_serialization",
        "-lrostime",
        "-lcpp_common",
        "-lboost_system",
    ]
    result = subprocess.run(["g++", "-O2", "-o", str(tmp), str(src), *libs, "-lpthread"], capture_output=True)
    if result.returncode != 0:
        print(f"{name} reference did not build:", result.stderr.decode()[-500:])
        return None
    os.replace(tmp, out)
    return str(out)


import node_roscpp  # noqa: E402  (it builds with cpp_program, above)

#: With the native reference, for the scenarios the C++ program implements.
IMPLS_CPP = IMPLS + ([CPP] if have_ros1() and node_roscpp.binary() else [])
#: CPU placements: both processes on one CPU, or one each.
SAME_CPU = ("0", "0")
CROSS_CPU = ("0", "1")


class Role:
    """A role process; stdout lines are collected by a thread."""

    def __init__(self, impl: str, master_uri: str, role: str, *args: str, cpu: str | None = None) -> None:
        if impl == CPP:
            cmd = [str(node_roscpp.binary()), role, *args]
        else:
            cmd = [sys.executable if impl == OURS else ROS1_PYTHON, ROLES, role, *args]
        if cpu is not None:
            cmd = ["taskset", "-c", cpu, *cmd]
        if impl == OURS:
            env = dict(os.environ, ROS_MASTER_URI=master_uri, ROS_HOSTNAME="localhost")
        else:
            env = ros1_env(master_uri)
        env["ROS_HOME"] = tempfile.mkdtemp(prefix="bench_node_home_")
        self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        self.lines: list[str] = []
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for raw in iter(self.proc.stdout.readline, b""):
            with self._cond:
                self.lines.append(raw.decode("utf-8", "replace").strip())
                self._cond.notify_all()

    def wait_line(self, predicate, timeout: float = 60.0) -> str | None:
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self.lines:
                    if predicate(line):
                        return line
                left = deadline - time.monotonic()
                if left <= 0 or (self.proc.poll() is not None and not self._thread.is_alive()):
                    return None
                self._cond.wait(min(left, 0.2))

    def ready(self, timeout: float = 60.0) -> None:
        if self.wait_line(lambda line: line == "ready", timeout) is None:
            raise RuntimeError(f"{self.proc.args} never became ready")

    def result(self, timeout: float = 120.0) -> dict:
        line = self.wait_line(lambda line: line.startswith("{"), timeout)
        if line is None:
            raise RuntimeError(f"{self.proc.args} gave no result")
        return json.loads(line)

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


@contextmanager
def master() -> Iterator[str]:
    """A master for the whole benchmark run; yields its URI."""
    port = free_port()
    uri = f"http://localhost:{port}/"
    if have_ros1():
        cmd = ["/usr/bin/rosmaster", "--core", "-p", str(port), "-w", "3"]
        env = ros1_env(uri)
    else:
        cmd = [ninjemys_bin("roscore"), "-p", str(port)]
        env = dict(os.environ, ROS_HOME=tempfile.mkdtemp(prefix="bench_node_home_"))
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    client = MasterClient(uri, "/bench", timeout=1.0)
    try:
        deadline = time.monotonic() + 20
        while not client.is_online():
            if time.monotonic() > deadline:
                raise RuntimeError("master did not start")
            time.sleep(0.05)
        yield uri
    finally:
        client.close()
        proc.kill()
        proc.wait()


@contextmanager
def roles(*items: Role) -> Iterator[tuple[Role, ...]]:
    try:
        yield items
    finally:
        for item in items:
            item.kill()


def ratio(ours: float, theirs: float) -> str:
    if not theirs or theirs != theirs or ours != ours:
        return "n/a"
    return f"{ours / theirs:.2f}x"


def header(title: str) -> None:
    print(f"\n## {title}  (machine shared: {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f})")
