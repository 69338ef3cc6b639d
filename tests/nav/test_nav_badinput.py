"""Bad input to the navigation nodes: one clear line naming the problem, and the node keeps running."""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path

import pytest
import yaml

from ninjemys.testing import NodeProcess, ninjemys_bin, ros1_env, run_master, wait_until


@pytest.fixture
def master(tmp_path):
    with run_master() as uri:
        yield dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=str(tmp_path / "ros_home"), PYTHONUNBUFFERED="1")


def run_node(env: dict[str, str], args: list[str], wait_for: str, timeout: float = 30.0) -> tuple[str, bool]:
    """Start ``rosrun <args>``, wait until ``wait_for`` shows up in its output; (output, still running
    a second later)."""
    with NodeProcess([ninjemys_bin("rosrun"), *args], env=env, merge_stderr=True) as proc:
        proc.wait_for(lambda line: wait_for in line, timeout)
        time.sleep(1.0)  # the node must outlive the bad input, not just report it
        alive = proc.proc.poll() is None
        proc.stop()
        return proc.text(), alive


def test_map_that_does_not_load(master, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.6\nfree_thresh: 0.2\n"
    )
    out, alive = run_node(master, ["map_server", "map_server", str(bad)], "expected a number > 0")
    lines = [line for line in out.splitlines() if "bad.yaml" in line]
    assert len(lines) == 1 and "bad.yaml:2: resolution: expected a number > 0, got -1" in lines[0]
    assert "Traceback" not in out
    assert alive


def test_move_base_parameter_of_the_wrong_type(master, tmp_path):
    params = tmp_path / "params.yaml"
    params.write_text(
        yaml.safe_dump({"global_costmap": {"inflation_radius": "wide", "observation_sources": ""}})
    )
    subprocess.run(
        [ninjemys_bin("rosparam"), "load", str(params), "/move_base"], env=master, check=True, timeout=30
    )
    out, alive = run_node(master, ["move_base", "move_base"], "inflation_radius")
    assert (
        "parameter /move_base/global_costmap/inflation_radius: expected a float, got 'wide'; using 0.55"
        in out
    )
    assert "Traceback" not in out
    assert alive


def test_map_saver_writes_what_map_server_reads(master, tmp_path):
    from ninjemys.maps.mapfile import load_map

    share = os.path.join(os.path.dirname(__file__), "..", "..", "src", "ninjemys", "packages", "share")
    maze = os.path.abspath(os.path.join(share, "puzzlebot_sim", "maps", "maze.yaml"))
    with NodeProcess([ninjemys_bin("rosrun"), "map_server", "map_server", maze], env=master):
        saver = subprocess.run(
            [ninjemys_bin("rosrun"), "map_server", "map_saver", "-f", str(tmp_path / "copy")],
            env=master,
            capture_output=True,
            text=True,
            timeout=60,
        )
    assert saver.returncode == 0, saver.stderr
    original, copy = load_map(maze), load_map(tmp_path / "copy.yaml")
    assert copy.data.shape == original.data.shape and copy.origin == original.origin
    assert (copy.data == original.data).all()


@pytest.mark.ros1
def test_move_base_tunables_through_ros1_dynparam(master, tmp_path):
    """ROS 1's own dynparam client changes the DWA's max_vel_x on a running move_base."""
    proc = NodeProcess([ninjemys_bin("rosrun"), "move_base", "move_base"], env=master, merge_stderr=True)
    # Debian's dynparam calls roslib.load_manifest('dynamic_reconfigure'), and Debian ships no package.xml
    share = tmp_path / "share" / "dynamic_reconfigure"
    share.mkdir(parents=True)
    xml = (
        Path(__file__).parents[2] / "src" / "ninjemys" / "interfaces" / "dynamic_reconfigure" / "package.xml"
    )
    (share / "package.xml").write_text(xml.read_text())
    env = ros1_env(master["ROS_MASTER_URI"], ROS_PACKAGE_PATH=str(tmp_path / "share"))
    try:
        dynparam = ["/usr/bin/python3", "/usr/lib/dynamic_reconfigure/dynparam"]  # Debian's

        def dwa_config() -> subprocess.CompletedProcess | None:
            got = subprocess.run(
                [*dynparam, "get", "/move_base/DWAPlannerROS"],
                env=env,
                capture_output=True,
                text=True,
                timeout=30,
            )
            return got if got.returncode == 0 and "max_vel_x" in got.stdout else None

        got = wait_until(dwa_config, 40.0, "move_base's DWAPlannerROS through Debian's dynparam", step=1.0)
        assert "'max_vel_x': 0.3" in got.stdout, got.stdout + got.stderr
        subprocess.run(
            [*dynparam, "set", "/move_base/DWAPlannerROS", "max_vel_x", "0.2"],
            env=env,
            check=True,
            timeout=30,
        )
        got = subprocess.run(
            [*dynparam, "get", "/move_base/DWAPlannerROS"],
            env=env,
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert "'max_vel_x': 0.2" in got.stdout
        assert proc.proc.poll() is None, proc.describe()
    finally:
        proc.stop()
