"""Shared helpers of the gateway benchmarks: the gateway as its own process, its CPU time, clients.

The gateway runs exactly as users start it (``rosrun rosbridge_server rosbridge_websocket``, here
through ``ninjemys.packages.run_shipped``), so its CPU is measured alone from /proc.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ninjemys.testing import free_port  # noqa: E402

_TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process ``pid`` so far (all its threads)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / _TICK


def pct(values: list[float], q: float) -> float:
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


class GatewayProcess:
    """``rosbridge_websocket`` on a free port, talking to ``master_uri``."""

    def __init__(self, master_uri: str, *params: str) -> None:
        self.port = free_port()
        env = dict(
            os.environ,
            ROS_MASTER_URI=master_uri,
            ROS_HOSTNAME="localhost",
            ROS_HOME=tempfile.mkdtemp(prefix="bench_bridge_home_"),
        )
        cmd = [
            sys.executable,
            "-m",
            "ninjemys.packages.run_shipped",
            "rosbridge_server",
            "rosbridge_websocket",
            f"_port:={self.port}",
            *params,
        ]
        self.proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline or self.proc.poll() is not None:
                    raise RuntimeError("the gateway did not start") from None
                time.sleep(0.1)
        self.url = f"ws://127.0.0.1:{self.port}/"

    def cpu(self) -> float:
        return cpu_seconds(self.proc.pid)

    def stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


@contextmanager
def gateway(master_uri: str, *params: str) -> Iterator[GatewayProcess]:
    proc = GatewayProcess(master_uri, *params)
    try:
        yield proc
    finally:
        proc.stop()
