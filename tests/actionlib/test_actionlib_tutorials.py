"""``rosrun actionlib_tutorials ...``: the Fibonacci and Averaging tutorials end to end, on simulated time.

The tutorial programs pace themselves in ROS time (one Fibonacci number per second, numbers at
20 Hz), so the test runs the graph on ``/use_sim_time`` with a /clock five times faster than real
time: the whole Fibonacci tutorial (19 simulated seconds) takes about four.
"""

from __future__ import annotations

import os
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.node import Node
from ninjemys.testing import kill_tree, ninjemys_bin, run_master
from rosgraph_msgs.msg import Clock

SPEED = 5.0
TICK = 0.005  # wall seconds between /clock messages


@pytest.fixture
def sim_graph(tmp_path: Path) -> Iterator[dict[str, str]]:
    """A master with /use_sim_time set and a /clock running SPEED times real time; the env for nodes."""
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1")
    env.pop("ROS_NAMESPACE", None)
    with run_master(env=env) as uri:
        env["ROS_MASTER_URI"] = uri
        clock_node = Node("sim_clock", master_uri=uri)
        clock_node.set_param("/use_sim_time", True)
        publisher = clock_node.publisher("/clock", Clock, queue_size=1)
        stop = threading.Event()

        def run() -> None:
            ns = 1_000_000_000
            while not stop.wait(TICK):
                ns += int(TICK * SPEED * 1e9)
                msg = Clock()
                msg.clock.secs, msg.clock.nsecs = divmod(ns, 1_000_000_000)
                publisher.publish(msg)

        thread = threading.Thread(target=run, daemon=True)
        thread.start()
        try:
            yield env
        finally:
            stop.set()
            thread.join()
            clock_node.shutdown()


def rosrun(env: dict[str, str], *args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [ninjemys_bin("rosrun"), *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )


def finish(proc: subprocess.Popen[str], timeout: float = 60) -> str:
    try:
        out, _ = proc.communicate(timeout=timeout)
    finally:
        kill_tree(proc)
    assert proc.returncode == 0, out
    return out


@pytest.fixture
def started(sim_graph: dict[str, str]) -> Iterator[list[subprocess.Popen[str]]]:
    procs: list[subprocess.Popen[str]] = []
    yield procs
    for proc in procs:
        kill_tree(proc)
        proc.communicate()


def test_fibonacci_server_and_both_clients(sim_graph: dict[str, str], started: list) -> None:
    started.append(rosrun(sim_graph, "actionlib_tutorials", "fibonacci_server"))
    out = finish(rosrun(sim_graph, "actionlib_tutorials", "fibonacci_client.py"))
    assert (
        "Result: 0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 233, 377, 610, 987, 1597, 2584, 4181, 6765"
        in out
    )
    out = finish(rosrun(sim_graph, "actionlib_tutorials", "fibonacci_client"))
    lines = [line for line in out.splitlines() if "Action" in line]
    assert lines[0].endswith("Action server started, sending goal.")
    assert lines[-1].endswith("Action finished: SUCCEEDED")


def test_averaging_server_client_and_number_source(sim_graph: dict[str, str], started: list) -> None:
    started.append(rosrun(sim_graph, "actionlib_tutorials", "averaging_server"))
    started.append(rosrun(sim_graph, "actionlib_tutorials", "gen_numbers.py"))
    out = finish(rosrun(sim_graph, "actionlib_tutorials", "averaging_client"))
    last = [line for line in out.splitlines() if "Action" in line][-1]
    assert last.endswith(("Action finished: SUCCEEDED", "Action finished: ABORTED")), out
