"""A subscriber that stops reading never slows the simulator (issue 23): its camera images are
dropped as ROS 1's queue_size drops them, and the physics goes on. The reader here is stopped
outright (SIGSTOP) while the simulator runs as fast as it can; the simulated clock must keep moving."""

from __future__ import annotations

import os
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from gazebo_helpers import Launched

from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node
from ninjemys.packages.shipped import shipped_executable
from ninjemys.testing import run_master

GetWorldProperties = get_service_class("gazebo_msgs/GetWorldProperties")

READER = """
import sys
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
node = Node("slow_reader", master_uri=sys.argv[1])
Image = get_message_class("sensor_msgs/Image")
def got(_msg):
    print("got an image", flush=True)
for topic in ("/camera/color/image_raw", "/camera/depth/image_rect_raw"):
    node.subscriber(topic, Image, got, queue_size=1)
node.spin()
"""


@pytest.fixture
def master() -> Iterator[str]:
    with run_master() as uri:
        yield uri


def sim_time(client: Node) -> float:
    proxy = client.service_proxy("/gazebo/get_world_properties", GetWorldProperties)
    try:
        return float(proxy().sim_time)
    finally:
        proxy.close()


def test_a_stopped_image_subscriber_does_not_stop_the_simulation(master: str, tmp_path: Path) -> None:
    env = dict(os.environ, ROS_MASTER_URI=master, PYTHONUNBUFFERED="1")
    cmd = shipped_executable("puzzlebot_sim", "sim_node").command(
        ["_world:=square", "_rate:=0", "_gui:=false"]
    )
    sim = Launched(cmd, env, tmp_path / "sim.log")
    reader = Launched([sys.executable, "-c", READER, master], env, tmp_path / "reader.log")
    client = Node("lag_client", anonymous=True, master_uri=master)
    try:
        sim.wait_for("PuzzleBot simulator:")
        reader.wait_for("got an image")
        os.kill(reader.proc.pid, signal.SIGSTOP)
        time.sleep(1.0)  # the reader's socket buffers and ring slots fill up meanwhile
        before = sim_time(client)
        time.sleep(2.0)
        after = sim_time(client)
        # flat out the simulator runs many times faster than real time; a publisher waiting for the
        # stopped reader would not advance at all (the bound is generous: the machine is shared)
        assert after - before > 1.0, f"simulated time went from {before:.3f} s to {after:.3f} s in 2 s"
    finally:
        client.shutdown("test over")
        try:
            os.kill(reader.proc.pid, signal.SIGCONT)
        except ProcessLookupError:
            pass
        reader.stop()
        sim.stop()
        for proc in (reader.proc, sim.proc):
            if proc.poll() is None:
                proc.kill()
                proc.wait(10)
    assert "Traceback" not in sim.log(), sim.log()
