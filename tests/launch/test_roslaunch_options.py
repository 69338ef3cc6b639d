"""roslaunch options and forms: -p, an existing master, output=log files, stdin, <machine> over ssh."""

from __future__ import annotations

import signal
import socket
import subprocess
import time
from pathlib import Path

from ninjemys.launch.master_link import master_is_up
from ninjemys.master.client import MasterClient
from ninjemys.testing import free_port, ninjemys_bin

from .conftest import Launch, run_cli, write_launch

SLEEPER = '<node name="solo" pkg="corpus_run" type="sleeper.py" output="{output}"/>'


def test_port_option_starts_master_on_that_port(tmp_path: Path, env: dict, launches: list) -> None:
    port = free_port()
    launch = Launch(["-p", str(port), str(write_launch(tmp_path, SLEEPER.format(output="screen")))], env)
    launches.append(launch)
    assert launch.wait_for(lambda ls: any("solo ready" in line for line in ls))
    assert master_is_up(f"http://localhost:{port}/")
    assert any(f"ROS_MASTER_URI=http://localhost:{port}/" in line for line in launch.lines)
    launch.proc.send_signal(signal.SIGINT)
    assert launch.finish() == 0
    assert not master_is_up(f"http://localhost:{port}/")


def test_existing_master_is_used_and_left_running(tmp_path: Path, env: dict, launches: list) -> None:
    port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
    core = subprocess.Popen(
        [ninjemys_bin("roscore"), "-p", port], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        launch = Launch(["--wait", str(write_launch(tmp_path, SLEEPER.format(output="log")))], env)
        launches.append(launch)
        assert launch.wait_for(lambda ls: any("started with pid" in line for line in ls))
        assert not any("auto-starting" in line for line in launch.lines)
        client = MasterClient(env["ROS_MASTER_URI"], "/test")
        run_id = client.get_param("/run_id")
        client.close()
        log = Path(env["ROS_HOME"]) / "log" / run_id / "solo-1-stdout.log"
        deadline = time.monotonic() + 60
        while log.read_text() != "solo ready\n" and time.monotonic() < deadline:
            time.sleep(0.05)
        assert log.read_text() == "solo ready\n"
        assert not any("solo ready" in line for line in launch.lines)
        launch.proc.send_signal(signal.SIGINT)
        assert launch.finish() == 0
        assert master_is_up(env["ROS_MASTER_URI"])
    finally:
        core.send_signal(signal.SIGINT)
        try:
            core.wait(10)
        except subprocess.TimeoutExpired:
            core.kill()
            core.wait()


def test_launch_xml_from_stdin(env: dict) -> None:
    xml = "<launch><node name='piped' pkg='corpus_run' type='sleeper.py'/></launch>"
    result = subprocess.run(
        [ninjemys_bin("roslaunch"), "--nodes", "-"],
        input=xml,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout == "/piped\n"


REMOTE = (
    '<machine name="faraway" address="192.0.2.1" timeout="1"/>\n'
    '<node name="remote" pkg="corpus_run" type="sleeper.py" machine="faraway"/>'
)


def test_unreachable_ssh_machine_is_named_and_nothing_starts(tmp_path: Path, env: dict) -> None:
    env["ROS_MASTER_URI"] = env["ROS_MASTER_URI"].replace("localhost", socket.gethostname())
    result = run_cli([str(write_launch(tmp_path, REMOTE))], env)
    assert result.returncode != 0
    errors = [line for line in result.stderr.splitlines() if line.startswith("ERROR")]
    assert len(errors) == 1, result.stderr
    assert "cannot reach machine [faraway]" in errors[0] or "[faraway] (192.0.2.1) needs ssh" in errors[0]
    assert not master_is_up(env["ROS_MASTER_URI"])


def test_remote_machine_with_loopback_master_uri_is_refused(tmp_path: Path, env: dict) -> None:
    result = run_cli([str(write_launch(tmp_path, REMOTE))], env)
    assert result.returncode != 0
    assert "machine [faraway] (192.0.2.1) cannot reach a master at http://localhost:" in result.stderr
    assert not master_is_up(env["ROS_MASTER_URI"])


def test_local_option_skips_remote_nodes(tmp_path: Path, env: dict, launches: list) -> None:
    body = (
        '<machine name="faraway" address="192.0.2.1" timeout="1"/>\n'
        '<node name="remote" pkg="corpus_run" type="sleeper.py" machine="faraway"/>\n'
        + SLEEPER.format(output="screen")
    )
    launch = Launch(["--local", str(write_launch(tmp_path, body))], env)
    launches.append(launch)
    assert launch.wait_for(lambda ls: any("solo ready" in line for line in ls)), "".join(launch.lines)
    assert not any("cannot reach machine" in line for line in launch.lines)
    launch.proc.send_signal(signal.SIGINT)
    assert launch.finish() == 0


FAKE_SSH = """#!/bin/sh
# A stand-in for ssh: "connects" by running the remote command locally (the last argument).
for last; do :; done
[ "$last" = "true" ] && exit 0
echo "fake-ssh ran on $1-style host" >&2
exec sh -c "$last"
"""


def test_remote_machine_runs_node_over_ssh(tmp_path: Path, env: dict, launches: list) -> None:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "ssh").write_text(FAKE_SSH)
    (bin_dir / "ssh").chmod(0o755)
    env["PATH"] = f"{bin_dir}:{Path(ninjemys_bin('rosrun')).parent}:{env['PATH']}"
    env["ROS_MASTER_URI"] = env["ROS_MASTER_URI"].replace("localhost", socket.gethostname())
    body = (
        '<machine name="faraway" address="192.0.2.1" user="robot"/>\n'
        '<node name="remote" pkg="corpus_run" type="sleeper.py" machine="faraway" output="screen"/>'
    )
    launch = Launch([str(write_launch(tmp_path, body))], env)
    launches.append(launch)
    assert launch.wait_for(lambda ls: any("remote ready" in line for line in ls)), "".join(launch.lines)
    launch.proc.send_signal(signal.SIGINT)
    assert launch.finish() == 0
