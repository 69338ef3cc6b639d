"""The tf commands: static_transform_publisher (tf2_ros and tf), tf_echo, tf_monitor, view_frames."""

from __future__ import annotations

import os
import re
import selectors
import subprocess
import sys
import time
from collections.abc import Iterator

import pytest

from ninjemys import testing
from ninjemys.tools.tf_echo import format_transform
from ninjemys.tools.tf_monitor import Monitor
from ninjemys.tools.view_frames import edges_from_dot, generate_dot, write_graph, write_outputs


def shipped(pkg: str, exe: str, *args: str) -> list[str]:
    return [sys.executable, "-m", "ninjemys.packages.run_shipped", pkg, exe, *args]


@pytest.fixture
def env() -> Iterator[dict[str, str]]:
    with testing.run_master() as uri:
        e = dict(os.environ)
        e["ROS_MASTER_URI"] = uri
        yield e


@pytest.fixture
def procs() -> Iterator[list[subprocess.Popen]]:
    started: list[subprocess.Popen] = []
    yield started
    for p in started:
        testing.kill_tree(p)


def read_until(proc: subprocess.Popen, pattern: str, count: int, timeout: float = 20.0) -> str:
    """stdout of ``proc`` until ``pattern`` has appeared ``count`` times (and that block is complete)."""
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    out = ""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if sel.select(0.2):
            line = proc.stdout.readline()
            if not line:
                break
            out += line
            if out.count(pattern) >= count and "in RPY (degree)" in out.rsplit(pattern, 1)[1]:
                return out
    raise AssertionError(f"no {count} x {pattern!r} within {timeout} s:\n{out}")


def test_tf_echo_block_format():
    q = (0.0, 0.0, 0.24740395925452294, 0.9689124217106447)  # yaw 0.5
    assert format_transform(1_700_000_000_123_456_789, (1, 2, 4, *q)) == (
        "At time 1700000000.123\n"
        "- Translation: [1.000, 2.000, 4.000]\n"
        "- Rotation: in Quaternion [0.000, 0.000, 0.247, 0.969]\n"
        "            in RPY (radian) [0.000, 0.000, 0.500]\n"
        "            in RPY (degree) [0.000, 0.000, 28.648]\n"
    )


def test_static_publishers_and_tf_echo(env, procs):
    for cmd in (
        shipped("tf2_ros", "static_transform_publisher", "1", "2", "3", "0.5", "0", "0", "base", "laser"),
        shipped("tf2_ros", "static_transform_publisher", "0", "0", "0", "0", "0", "0", "1", "laser", "cam"),
        shipped("tf", "static_transform_publisher", "0", "0", "1", "0", "0", "0", "map", "base", "50"),
    ):
        procs.append(subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    echo = subprocess.Popen(
        shipped("tf", "tf_echo", "map", "cam", "5"),
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    procs.append(echo)
    out = read_until(echo, "At time", 2)
    block = out[out.index("At time") :]
    assert re.match(
        r"At time \d+\.\d{3}\n"
        r"- Translation: \[1\.000, 2\.000, 4\.000\]\n"
        r"- Rotation: in Quaternion \[0\.000, 0\.000, 0\.247, 0\.969\]\n"
        r"            in RPY \(radian\) \[0\.000, 0\.000, 0\.500\]\n"
        r"            in RPY \(degree\) \[0\.000, 0\.000, 28\.648\]\n",
        block,
    ), out


def test_static_transform_publisher_argument_errors(env):
    done = subprocess.run(
        shipped("tf2_ros", "static_transform_publisher", "1", "2"), env=env, capture_output=True, text=True
    )
    assert done.returncode == 255
    assert "Usage: static_transform_publisher x y z yaw pitch roll frame_id child_frame_id" in done.stdout
    assert "exited due to not having the right number of arguments" in done.stderr
    done = subprocess.run(
        shipped("tf2_ros", "static_transform_publisher", "0", "0", "0", "0", "0", "0", "a", "a"),
        env=env,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 1
    assert "target_frame and source frame are the same (a, a) this cannot work" in done.stderr
    done = subprocess.run(shipped("tf", "tf_echo", "a"), env=env, capture_output=True, text=True, timeout=30)
    assert done.returncode == 255 and done.stdout.startswith(
        "Usage: tf_echo source_frame target_frame [echo_rate]"
    )


def test_tf_monitor_report():
    m = Monitor()
    m.record([("base", 9.9), ("odom", 9.8)], "/robot", now=10.0)
    m.record([("base", 10.0), ("odom", 10.0)], "/robot", now=10.5)
    m.record([("laser", None)], "/stp(static)", now=10.5)
    frames, heading, nodes = m.report(None)
    assert frames.splitlines()[2:] == [
        "Frame: base published by /robot Average Delay: 0.3 Max Delay: 0.5",
        "Frame: laser published by /stp(static) Average Delay: 0 Max Delay: 0",
        "Frame: odom published by /robot Average Delay: 0.35 Max Delay: 0.5",
    ]
    assert heading == "\nAll Broadcasters:\n"
    assert nodes.splitlines()[0] == "Node: /robot 4 Hz, Average Delay: 0.325 Max Delay: 0.5"
    assert "base" not in m.report(["laser"])[0]


def test_view_frames_outputs(tmp_path, monkeypatch):
    data = {
        "odom": {
            "parent": "map",
            "broadcaster": "/amcl",
            "rate": 20.0,
            "buffer_length": 4.9,
            "most_recent_transform": 12.5,
            "oldest_transform": 7.6,
        },
        "base": {
            "parent": "odom",
            "broadcaster": "/odom",
            "rate": 50.0,
            "buffer_length": 4.98,
            "most_recent_transform": 12.5,
            "oldest_transform": 7.52,
        },
    }
    dot = generate_dot(data, 13.0)
    assert dot.startswith('digraph G {\n"map" -> "odom"[label=" Broadcaster: /amcl\\nAverage rate: 20.0\\n')
    assert dot.endswith('"Recorded at time: 13.0"[ shape=plaintext ] ;\n}->"map";\n}')
    assert generate_dot({}, 1.0) == 'digraph G { "No tf data received" }'
    monkeypatch.setattr("shutil.which", lambda _name: None)
    written = write_outputs(data, 13.0, tmp_path)
    assert [p.name for p in written] == ["frames.gv", "frames.svg"]
    svg = (tmp_path / "frames.svg").read_text()
    assert svg.startswith("<svg") and ">odom</text>" in svg and "Broadcaster: /amcl" in svg


def test_tf_view_frames_draws_tf_dot_text(tmp_path, monkeypatch):
    """``rosrun tf view_frames`` writes tf's own dot text (allFramesAsDot) and draws it without dot."""
    from ninjemys.tf2.core import BufferCore

    b = BufferCore()
    b.set_transforms(
        [("map", "odom", 10**9, 0, 0, 0, 0, 0, 0, 1), ("odom", "base", 10**9, 0, 0, 0, 0, 0, 0, 1)], "/me"
    )
    dot = b.all_frames_as_dot(12.0)
    edges = edges_from_dot(dot)
    assert edges[1] == (
        "odom",
        "base",
        [
            "Broadcaster: /me",
            "Average rate: 10000.000 Hz",
            "Most recent transform: 1.000 ( 11.000 sec old)",
            "Buffer length: 0.000 sec",
        ],
    )
    monkeypatch.setattr("shutil.which", lambda _name: None)
    written = write_graph(dot, edges, 12.0, tmp_path)
    assert (tmp_path / "frames.gv").read_text() == dot
    assert written[-1].name == "frames.svg" and ">base</text>" in written[-1].read_text()


@pytest.mark.slow
def test_view_frames_end_to_end(env, procs, tmp_path):
    procs.append(
        subprocess.Popen(
            shipped("tf2_ros", "static_transform_publisher", "1", "0", "0", "0", "0", "0", "base", "laser"),
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    )
    done = subprocess.run(
        shipped("tf2_tools", "view_frames.py"),
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert "Listening to tf data during 5 seconds..." in done.stdout + done.stderr
    gv = (tmp_path / "frames.gv").read_text()
    assert '"base" -> "laser"[label=" Broadcaster: /static_transform_publisher' in gv
    assert (tmp_path / "frames.pdf").exists() or (tmp_path / "frames.svg").exists()


def test_example_broadcaster_and_listener(env, procs):
    from pathlib import Path

    examples = Path(__file__).parents[2] / "examples" / "tf"
    procs.append(
        subprocess.Popen(
            [sys.executable, str(examples / "frame_broadcaster.py")], env=env, stderr=subprocess.DEVNULL
        )
    )
    listener = subprocess.Popen(
        [sys.executable, str(examples / "frame_listener.py")],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    procs.append(listener)
    sel = selectors.DefaultSelector()
    sel.register(listener.stdout, selectors.EVENT_READ)
    deadline = time.monotonic() + 30
    seen = ""
    while "carrot in laser" not in seen and time.monotonic() < deadline:
        if sel.select(0.2):
            seen += listener.stdout.readline()
    assert re.search(r"carrot in laser: x=-?\d+\.\d\d y=-?\d+\.\d\d yaw=-?\d+\.\d\d", seen), seen
