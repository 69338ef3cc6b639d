"""Test harness shared by the node and interop tests: a restartable master process (polling waits and
child processes live in :mod:`ninjemys.testing`)."""

from __future__ import annotations

import subprocess

from ninjemys import testing
from ninjemys.master.client import MasterClient
from ninjemys.testing import wait_until


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
            wait_until(client.is_online, timeout=15.0, what=f"the master on port {self.port}")
        finally:
            client.close()

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None
