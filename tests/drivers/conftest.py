"""The drivers' test harness: a master, the environment a driver process runs in, the emulated devices
and the driver processes and nodes a test starts, all torn down in one place (processes first, then
nodes, then devices, then the master) so each test says only what it drives and checks."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Protocol, TypeVar

import pytest

from ninjemys import testing
from ninjemys.node import Node


class Collect:
    """A subscriber callback that keeps every message and lets the test wait for them."""

    def __init__(self) -> None:
        self.items: list[Any] = []
        self.cond = threading.Condition()

    def __call__(self, msg: Any) -> None:
        with self.cond:
            self.items.append(msg)
            self.cond.notify_all()

    def wait_count(self, n: int, timeout: float = 20.0) -> None:
        with self.cond:
            if not self.cond.wait_for(lambda: len(self.items) >= n, timeout):
                raise AssertionError(f"{len(self.items)} messages received, wanted {n}")

    def wait_for(self, pred: Callable[[Any], bool], timeout: float = 20.0) -> Any:
        """The newest message for which ``pred`` holds, once there is one."""
        found: list[Any] = []

        def check() -> bool:
            found[:] = [m for m in self.items if pred(m)]
            return bool(found)

        with self.cond:
            if not self.cond.wait_for(check, timeout):
                raise AssertionError(f"no matching message in {len(self.items)} received")
        return found[-1]


class _Device(Protocol):
    def close(self) -> None: ...


D = TypeVar("D", bound=_Device)


class Rig:
    """What one driver test runs against; see the module docstring."""

    def __init__(self, env: dict[str, str], uri: str) -> None:
        self.env = env
        self.uri = uri
        self._procs: list[tuple[subprocess.Popen, bool]] = []  # (process, started as a group)
        self._nodes: list[Node] = []
        self._devices: list[_Device] = []

    def device(self, device: D) -> D:
        """An emulated device, closed when the test ends."""
        self._devices.append(device)
        return device

    def node(self, name: str) -> Node:
        node = Node(name, master_uri=self.uri)
        self._nodes.append(node)
        return node

    def collect(self, node: Node, topic: str, msg_class: Any) -> Collect:
        """Every message of ``topic``, as ``node`` receives it."""
        got = Collect()
        node.subscriber(topic, msg_class, got)
        return got

    def shipped(self, package: str, executable: str, *args: str, quiet: bool = False) -> subprocess.Popen:
        """One of our shipped nodes (``rosrun package executable args``), its output kept (or dropped)."""
        out = subprocess.DEVNULL if quiet else subprocess.PIPE
        proc = subprocess.Popen(
            [sys.executable, "-m", "ninjemys.packages.run_shipped", package, executable, *args],
            env=self.env,
            stdout=out,
            stderr=subprocess.DEVNULL if quiet else subprocess.STDOUT,
            text=True,
        )
        self._procs.append((proc, False))
        return proc

    def roslaunch(self, package: str, launch_file: str, *args: str) -> subprocess.Popen:
        """``roslaunch package launch_file args`` in a session of its own (stopped as a group)."""
        proc = subprocess.Popen(
            [testing.ninjemys_bin("roslaunch"), package, launch_file, *args],
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,
        )
        self._procs.append((proc, True))
        return proc

    def stop(self, proc: subprocess.Popen) -> str:
        """Ctrl-C, as a user stops a driver; killed with its children after 20 s. Returns its output."""
        group = next((g for p, g in self._procs if p is proc), False)
        if proc.poll() is None:
            if group:
                os.killpg(proc.pid, signal.SIGINT)
            else:
                proc.send_signal(signal.SIGINT)
        try:
            out, _ = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            testing.kill_tree(proc)
            out, _ = proc.communicate()
        return out or ""

    def read_until(self, proc: subprocess.Popen, text: str, timeout: float = 30.0) -> str:
        """The output of ``proc`` up to a line holding ``text`` (a step a test must see happen before
        its next one: a process starting on a loaded machine may take seconds to get there). Read
        from the pipe itself, so that :meth:`stop` later returns the rest."""
        fd = proc.stdout.fileno()  # type: ignore[union-attr]
        got = b""
        deadline = time.monotonic() + timeout
        while text.encode() not in got:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([fd], [], [], max(0.0, left))
            chunk = os.read(fd, 65536) if ready else b""
            if not chunk:
                raise AssertionError(
                    f"no {text!r} in the output within {timeout:g} s: {got.decode(errors='replace')}"
                )
            got += chunk
        return got.decode(errors="replace")

    def exit_output(self, proc: subprocess.Popen) -> str:
        """The output of a driver that must give up by itself: non-zero exit, no traceback."""
        try:
            out, _ = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            return self.stop(proc) + "\n(did not exit)"
        assert proc.returncode != 0
        assert "Traceback" not in out, out
        return out

    def close(self) -> None:
        for proc, _ in self._procs:
            if proc.returncode is None:
                self.stop(proc)
        for node in self._nodes:
            node.shutdown()
        for device in self._devices:
            device.close()


@pytest.fixture
def rig(tmp_path: Path) -> Iterator[Rig]:
    """A master and a :class:`Rig` on it; logs and ROS_HOME in the test's tmp_path."""
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with testing.run_master(env=env) as uri:
        env["ROS_MASTER_URI"] = uri
        r = Rig(env, uri)
        try:
            yield r
        finally:
            r.close()
