"""gazebo_ros' ``/gazebo/pub_clock_frequency`` (empty_world.launch's use_clock_frequency and
pub_clock_frequency): /clock goes out that many times per simulated second instead of every
physics step (issue 23 leftovers; it also spares a fast simulation most of its /clock messages)."""

from __future__ import annotations

import os
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from gazebo_helpers import Launched

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.packages.shipped import shipped_executable
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import World
from ninjemys.testing import run_master, wait_until

Clock = get_message_class("rosgraph_msgs/Clock")


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def clock_stamps(client: Node, seconds: float) -> list[float]:
    got: list[float] = []
    lock = threading.Lock()

    def keep(msg: Any) -> None:
        with lock:
            got.append(msg.clock.to_sec())

    sub = client.subscriber("/clock", Clock, keep, queue_size=1000)
    try:
        wait_until(lambda: len(got) >= 3, 15, "/clock messages")
        threading.Event().wait(seconds)
    finally:
        sub.unregister()
    with lock:
        return list(got)


def test_every_step_by_default_and_at_the_asked_frequency_otherwise(master: str) -> None:
    node = Node("clock_sim", master_uri=master)
    client = Node("clock_client", anonymous=True, master_uri=master)
    try:
        sn = SimNode(node, NodeLog(node.name), Simulation(World("empty"), 0.01), 0.0, None)
        got: list[float] = []
        client.subscriber("/clock", Clock, lambda m: got.append(m.clock.to_sec()), queue_size=1000)
        wait_until(lambda: sn.clock_pub.get_num_connections() > 0, 10, "the /clock subscriber")
        for _ in range(50):
            sn._step_and_publish()
        wait_until(lambda: len(got) >= 50, 10, "50 clocks")
        assert got[:50] == pytest.approx([0.01 * (i + 1) for i in range(50)])
        got.clear()
        sn.clock_period = 0.05  # 20 Hz of simulated time
        for _ in range(100):
            sn._step_and_publish()
        wait_until(lambda: len(got) >= 20, 10, "20 clocks")
        threading.Event().wait(0.2)
        assert len(got) == 20
        assert [round(b - a, 6) for a, b in zip(got, got[1:], strict=False)] == [0.05] * 19
    finally:
        client.shutdown("test over")
        node.shutdown("test over")


def test_the_gazebo_parameter_sets_it_for_the_simulator_node(master: str, tmp_path: Path) -> None:
    client = Node("clock_param_client", anonymous=True, master_uri=master)
    client.set_param("/gazebo/pub_clock_frequency", 10)
    cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
        ["_world:=square", "_rate:=4", "_gui:=false"]
    )
    sim = Launched(cmd, dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1"), tmp_path / "sim.log")
    try:
        sim.wait_for("PuzzleBot simulator:")
        stamps = clock_stamps(client, 1.0)
        gaps = {round(b - a, 6) for a, b in zip(stamps, stamps[1:], strict=False)}
        assert gaps == {0.1}, sorted(gaps)
    finally:
        client.shutdown("test over")
        sim.stop()
