"""roslaunch end to end (our roscore auto-started): 20-node Ctrl-C, required, respawn, bad input."""

from __future__ import annotations

import re
import signal
import time
from pathlib import Path

import pytest

from ninjemys.launch.master_link import master_is_up

from .conftest import Launch, alive, run_cli, write_launch


def test_ctrl_c_stops_twenty_nodes_quickly_and_leaves_nothing(
    tmp_path: Path, env: dict, launches: list
) -> None:
    nodes = "\n".join(
        f'<node name="n{i}" pkg="corpus_run" type="sleeper.py" output="screen"/>' for i in range(20)
    )
    launch = Launch([str(write_launch(tmp_path, nodes))], env)
    launches.append(launch)
    # output passes through unchanged: twenty unbuffered nodes may interleave their writes mid-line
    assert launch.wait_for(lambda ls: len(re.findall(r"n\d+ ready", "".join(ls))) == 20, timeout=90), "".join(
        launch.lines
    )
    pids = launch.pids()
    assert len(pids) == 21  # the auto-started master and 20 nodes
    start = time.monotonic()
    launch.proc.send_signal(signal.SIGINT)
    code = launch.finish(timeout=30)
    elapsed = time.monotonic() - start
    assert code == 0
    assert elapsed < 3.0, f"shutdown took {elapsed:.2f}s"
    assert not [pid for pid in pids if alive(pid)]
    assert not master_is_up(env["ROS_MASTER_URI"])


def test_required_node_death_ends_launch_with_failure(tmp_path: Path, env: dict, launches: list) -> None:
    body = (
        '<node name="keeper" pkg="corpus_run" type="sleeper.py" output="screen"/>\n'
        '<node name="fragile" pkg="corpus_run" type="crasher.py" args="0.5" required="true" output="screen"/>'
    )
    launch = Launch([str(write_launch(tmp_path, body))], env)
    launches.append(launch)
    code = launch.finish(timeout=90)
    text = "".join(launch.lines)
    assert code != 0, text
    assert "REQUIRED process [fragile-2] has died!" in text
    assert not [pid for pid in launch.pids() if alive(pid)]


def test_respawn_restarts_crashing_node(tmp_path: Path, env: dict, launches: list) -> None:
    body = (
        '<node name="phoenix" pkg="corpus_run" type="crasher.py" args="0" respawn="true" '
        'respawn_delay="0.1" output="screen"/>'
    )
    launch = Launch([str(write_launch(tmp_path, body))], env)
    launches.append(launch)
    assert launch.wait_for(lambda ls: sum("restarting process" in line for line in ls) >= 3, timeout=90)
    launch.proc.send_signal(signal.SIGINT)
    assert launch.finish() == 0
    assert sum("crasher running" in line for line in launch.lines) >= 3


def test_params_are_set_on_the_master_before_nodes_start(tmp_path: Path, env: dict, launches: list) -> None:
    from ninjemys.master.client import MasterClient

    body = (
        '<param name="greeting" value="hi"/>\n'
        '<node name="holder" pkg="corpus_run" type="sleeper.py" output="screen"><param name="rate" value="5"/></node>'
    )
    launch = Launch([str(write_launch(tmp_path, body))], env)
    launches.append(launch)
    assert launch.wait_for(lambda ls: any("holder ready" in line for line in ls), timeout=90)
    client = MasterClient(env["ROS_MASTER_URI"], "/test")
    assert client.get_param("/greeting") == "hi"
    assert client.get_param("/holder/rate") == 5
    client.close()
    launch.proc.send_signal(signal.SIGINT)
    assert launch.finish() == 0


BAD = {
    "malformed": (
        '<node name="a" pkg="corpus_run" type="sleeper.py">',
        "test.launch:3: Invalid roslaunch XML syntax",
    ),
    "missing_arg": ('<param name="p" value="$(arg x)"/>', "arg 'x' is not set"),
    "find_missing": (
        '<param name="p" value="$(find missing_pkg)/x"/>',
        "$(find missing_pkg): Resource not found: missing_pkg",  # ROS 1's words, after file:line
    ),
    "unknown_machine": (
        '<node name="a" pkg="corpus_run" type="sleeper.py" machine="mars"/>',
        "unknown machine [mars]",
    ),
}


# A node whose package or executable is missing is not among these: ROS 1 reports it and starts the
# rest (tests/launch/test_launch_missing_nodes.py).
@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_clear_error_and_starts_nothing(case: str, tmp_path: Path, env: dict) -> None:
    body, expected = BAD[case]
    result = run_cli([str(write_launch(tmp_path, body))], env)
    assert result.returncode != 0
    errors = [line for line in result.stderr.splitlines() if line.startswith("ERROR")]
    assert len(errors) == 1, result.stderr
    assert expected in errors[0]
    assert "Traceback" not in result.stderr
    assert "started with pid" not in result.stdout
    assert not master_is_up(env["ROS_MASTER_URI"])


def test_unknown_tags_and_attributes_warn_like_ros1(tmp_path: Path, env: dict) -> None:
    body = '<foo/>\n<node name="a" pkg="corpus_run" type="sleeper.py" bogus="1"/>'
    result = run_cli(["--nodes", str(write_launch(tmp_path, body))], env)
    assert result.returncode == 0
    assert result.stdout == "/a\n"
    assert "unrecognized tag foo" in result.stderr
    assert "unknown <node> attribute 'bogus'" in result.stderr


def test_rosrun_form_is_accepted_and_announced(env: dict) -> None:
    result = run_cli(["--nodes", "corpus_run", "sleeper.py"], env)
    assert result.returncode == 0
    assert result.stdout == "/sleeper\n"
    assert "rosrun corpus_run sleeper.py" in result.stderr


def test_package_and_file_form_finds_the_launch_file(env: dict) -> None:
    result = run_cli(["--nodes", "corpus_b", "animals.launch"], env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["/dolphin", "/cat", "/listener"]
