"""Test harness shared by the node and interop tests: a restartable master process, polling waits,
and child processes whose output is collected line by line."""

from __future__ import annotations

import subprocess
import threading
import time
from collections.abc import Callable

from ninjemys import testing
from ninjemys.master.client import MasterClient


def wait_until(predicate: Callable[[], object], timeout: float = 5.0, step: float = 0.01) -> bool:
    """Poll ``predicate`` until it is truthy (test helper only)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return bool(predicate())


class MasterProcess:
    """A master in a child process on a fixed port, restartable (for master-restart tests)."""

    def __init__(self, port: int, kind: str = "ninjemys") -> None:
        self.port = port
        self.kind = kind
        self.uri = f"http://localhost:{port}/"
        self.proc: subprocess.Popen[bytes] | None = None

    def start(self) -> None:
        if self.kind == "ros1":
            cmd = ["/usr/bin/rosmaster", "--core", "-p", str(self.port), "-w", "3"]
            env = testing.ros1_env(self.uri)
        else:
            cmd = [testing.ninjemys_bin("roscore"), "-p", str(self.port)]
            env = None
        self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        client = MasterClient(self.uri, "/probe", timeout=1.0)
        try:
            if not wait_until(client.is_online, timeout=15.0, step=0.05):
                raise RuntimeError(f"master on port {self.port} did not come up")
        finally:
            client.close()

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


class Child:
    """A child process whose stdout lines are collected by a reader thread (never blocks the test)."""

    def __init__(self, cmd: list[str], env: dict[str, str] | None = None) -> None:
        self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.lines: list[str] = []
        self.errors: list[str] = []
        self._threads = [
            threading.Thread(target=self._read, args=(self.proc.stdout, self.lines), daemon=True),
            threading.Thread(target=self._read, args=(self.proc.stderr, self.errors), daemon=True),
        ]
        for t in self._threads:
            t.start()

    @staticmethod
    def _read(stream, into: list[str]) -> None:
        for raw in iter(stream.readline, b""):
            into.append(raw.decode("utf-8", "replace").rstrip("\n"))

    def wait_line(self, predicate: Callable[[str], bool], timeout: float = 15.0) -> bool:
        return wait_until(lambda: any(predicate(line) for line in list(self.lines)), timeout=timeout)

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        for t in self._threads:
            t.join(2)

    def describe(self) -> str:
        return f"stdout={self.lines[-5:]} stderr={self.errors[-10:]}"
