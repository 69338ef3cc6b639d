"""`python -m ninjemys.demo`: roscore + talker + listener with their logs on screen, cleaned up after."""

from __future__ import annotations

import os
import subprocess
import sys

from ninjemys.testing import free_port


def test_demo_runs_and_cleans_up(tmp_path) -> None:
    port = free_port()
    env = dict(os.environ, ROS_HOME=str(tmp_path))
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ninjemys.demo",
            "--chatter",
            "-p",
            str(port),
            "--duration",
            "6",
            "--no-color",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert any(line.startswith("[talker] [INFO] [") and "hello world" in line for line in lines), lines[:40]
    assert any(line.startswith("[listener] [INFO] [") and "I heard hello world" in line for line in lines), (
        lines
    )
    assert any(line.startswith("[roscore] ") for line in lines)
    # nothing the demo started is left running
    leftover = subprocess.run(["pgrep", "-f", f"-p {port}"], capture_output=True, text=True).stdout.split()
    assert leftover == []


def test_tutorial_start_up_error_is_one_line(tmp_path) -> None:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_MASTER_URI=f"http://localhost:{free_port()}/")
    done = subprocess.run(
        [sys.executable, "-m", "ninjemys.tutorials.talker", "_rate:=[1"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 1
    assert done.stderr.splitlines() == [
        "ERROR: invalid command-line parameter _rate:=[1: not valid YAML (expected ',' or ']', but got '<stream end>')"
    ]
