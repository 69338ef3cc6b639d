"""The tf tools (roscpp programs in ROS 1) started with no master: roscpp's one ERROR line, a wait,
"Connected to master" when it comes up, a quiet exit on Ctrl-C. Never a traceback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from graph_procs import ninjemys_env  # noqa: E402

from ninjemys.testing import free_port, kill_tree, ninjemys_bin, run_master  # noqa: E402

ROSCPP_TOOLS = {
    "tf_echo": ["tf", "tf_echo", "a", "b"],
    "tf_monitor": ["tf", "tf_monitor"],
    "static_transform_publisher": [
        "tf",
        "static_transform_publisher",
        "0",
        "0",
        "0",
        "0",
        "0",
        "0",
        "a",
        "b",
        "100",
    ],
    "buffer_server": ["tf2_ros", "buffer_server"],
}
FAILED = "[registerPublisher] Failed to contact master at [localhost:{port}].  Retrying..."


def _start(args: list[str], port: int) -> subprocess.Popen[str]:
    env = ninjemys_env(f"http://localhost:{port}")
    return subprocess.Popen(
        [ninjemys_bin("rosrun"), *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _read_until(stream, needle: str, timeout: float = 30.0) -> list[str]:
    seen: list[str] = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = stream.readline()
        if not line:
            break
        seen.append(line.rstrip("\n"))
        if needle in line:
            return seen
    raise AssertionError(f"never printed {needle!r}: {seen}")


@pytest.mark.parametrize("tool", sorted(ROSCPP_TOOLS))
def test_waits_for_the_master_and_ends_quietly_on_ctrl_c(tool: str) -> None:
    port = free_port()
    proc = _start(ROSCPP_TOOLS[tool], port)
    try:
        lines = _read_until(proc.stderr, FAILED.format(port=port))
        assert lines[-1].startswith("[ERROR] [")
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=20)
        assert proc.returncode == 0, err
        assert "Traceback" not in "\n".join(lines) + err
    finally:
        kill_tree(proc)


def test_tf_echo_goes_on_when_the_master_comes_up() -> None:
    port = free_port()
    proc = _start(ROSCPP_TOOLS["tf_echo"], port)
    try:
        _read_until(proc.stderr, FAILED.format(port=port))
        with run_master(port=port):
            connected = _read_until(proc.stdout, "Connected to master at")
            assert connected[-1].endswith(f"Connected to master at [localhost:{port}]")
            _read_until(proc.stdout, "Failure at")  # tf_echo's own output: it runs
            os.killpg(proc.pid, signal.SIGINT)
            _, err = proc.communicate(timeout=20)
        assert "Traceback" not in err
    finally:
        kill_tree(proc)
