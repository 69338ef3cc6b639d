"""The ``roscore`` command: summary, parameters, logs, port rules, refusal to double-start, shutdown."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.errors import MasterError
from ninjemys.master.client import MasterClient
from ninjemys.testing import free_port, ninjemys_bin


def _wait_ready(uri: str, proc: subprocess.Popen[str], timeout: float = 20) -> MasterClient:
    client = MasterClient(uri, "/test", timeout=5)
    deadline = time.monotonic() + timeout
    while True:
        try:
            client.get_pid()
            return client
        except MasterError:
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "roscore never answered"
            time.sleep(0.02)


@pytest.fixture
def roscore(tmp_path: Path) -> Iterator[tuple[subprocess.Popen[str], str, Path]]:
    port = free_port()
    env = dict(os.environ, ROS_HOME=str(tmp_path / "home"), ROS_HOSTNAME="localhost")
    proc = subprocess.Popen(
        [ninjemys_bin("roscore"), "-p", str(port)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        uri = f"http://localhost:{port}/"
        _wait_ready(uri, proc)
        yield proc, uri, tmp_path / "home"
    finally:
        proc.kill()
        proc.wait()


def test_core_parameters_summary_and_logs(roscore: tuple[subprocess.Popen[str], str, Path]) -> None:
    proc, uri, home = roscore
    client = MasterClient(uri, "/test")
    run_id = client.get_param("/run_id")
    assert client.get_param("/rosversion") == "1.15.15"
    assert client.get_param("/rosdistro")
    assert client.get_uri() == uri
    run_dir = home / "log" / run_id
    assert run_dir.is_dir()
    assert (home / "log" / "latest").resolve() == run_dir.resolve()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert "SUMMARY" in out and " * /rosversion: 1.15.15" in out
    assert f"ROS_MASTER_URI={uri}" in out
    assert f"setting /run_id to {run_id}" in out
    assert out.rstrip().endswith("done")
    assert "Traceback" not in err


def test_second_roscore_on_the_port_is_refused(roscore: tuple[subprocess.Popen[str], str, Path]) -> None:
    _, uri, home = roscore
    port = uri.rsplit(":", 1)[1].strip("/")
    second = subprocess.run(
        [ninjemys_bin("roscore"), "-p", port],
        env=dict(os.environ, ROS_HOME=str(home)),
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert second.returncode != 0
    lines = second.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ERROR: roscore cannot run as another roscore/master")


def test_port_in_use_by_something_else(tmp_path: Path) -> None:
    import socket

    with socket.socket() as s:
        s.bind(("0.0.0.0", 0))
        s.listen(1)
        port = s.getsockname()[1]
        res = subprocess.run(
            [ninjemys_bin("roscore"), "-p", str(port)],
            env=dict(os.environ, ROS_HOME=str(tmp_path)),
            capture_output=True,
            text=True,
            timeout=30,
        )
    assert res.returncode == 1
    assert res.stderr.strip().startswith("ERROR: port") and "Traceback" not in res.stderr


def test_port_from_ros_master_uri_and_log_dir(tmp_path: Path) -> None:
    port = free_port()
    uri = f"http://localhost:{port}/"
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_LOG_DIR=str(tmp_path / "logs"), ROS_HOSTNAME="localhost")
    proc = subprocess.Popen(
        [ninjemys_bin("roscore")], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    try:
        client = _wait_ready(uri, proc)  # type: ignore[arg-type]
        assert (tmp_path / "logs" / client.get_param("/run_id")).is_dir()
    finally:
        proc.kill()
        proc.wait()


def test_shutdown_call_stops_roscore(roscore: tuple[subprocess.Popen[str], str, Path]) -> None:
    proc, uri, _ = roscore
    MasterClient(uri, "/killer").shutdown("test over")
    proc.wait(timeout=10)
    assert proc.returncode == 0


def test_bad_arguments_are_one_line_errors(tmp_path: Path) -> None:
    res = subprocess.run(
        [ninjemys_bin("roscore"), "-p", "70000"],
        env=dict(os.environ, ROS_HOME=str(tmp_path)),
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert res.returncode == 1 and res.stderr.strip() == "ERROR: -p 70000: not a TCP port"


def test_rosout_node_comes_up(roscore: tuple[subprocess.Popen[str], str, Path]) -> None:
    proc, uri, home = roscore
    client = MasterClient(uri, "/test")
    deadline = time.monotonic() + 20
    while True:
        state = client.get_system_state()
        subs = dict((t, n) for t, n in state[1])
        pubs = dict((t, n) for t, n in state[0])
        if subs.get("/rosout") == ["/rosout"] and pubs.get("/rosout_agg") == ["/rosout"]:
            break
        assert time.monotonic() < deadline, state
        time.sleep(0.05)
    run_id = client.get_param("/run_id")
    assert (home / "log" / run_id / "rosout.log").read_text().startswith("\n\n")
