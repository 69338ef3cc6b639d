"""gazebo_ros_control beside a plugin drive (Husarion's ROSbot: a skid steer plugin drives, the
controller_manager runs over the transmissions' wheels): joint_state_controller loads from its own
yaml and publishes the four wheels, and cmd_vel still drives (tests/sim/packages/skid_control_test).
Ours took gazebo_ros_control for a second drive and started no manager: the spawner waited 30 s,
warned, and /joint_states stayed empty."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from gazebo_helpers import Launched

from ninjemys.sim.description.build import model_from_description
from ninjemys.testing import ninjemys_bin, run_master

PACKAGES = Path(__file__).parent / "packages"
URDF = PACKAGES / "skid_control_test" / "urdf" / "skidbot.urdf"
WHEELS = [f"{s}_wheel_hinge" for s in ("front_left", "front_right", "rear_left", "rear_right")]


def test_the_description_keeps_the_skid_steer_and_a_manager_beside_it() -> None:
    m = model_from_description(URDF.read_text(), str(URDF))
    assert m.drive.kind == "skid_steer" and m.control_beside is not None
    assert m.control_beside.controller_namespace == "/"
    assert m.control_joints == {
        "front_left_wheel_hinge": "left",
        "front_right_wheel_hinge": "right",
        "rear_left_wheel_hinge": "left",
        "rear_right_wheel_hinge": "right",
    }
    assert not any("second drive plugin" in w for w in m.warnings)
    # either order: gazebo_ros_control first, then the plugin
    text = URDF.read_text()
    skid = text[
        text.index('  <gazebo>\n    <plugin name="skid"') : text.index(
            '  <gazebo>\n    <plugin name="gazebo_ros_control"'
        )
    ]
    swapped = text.replace(skid, "").replace("</robot>", skid + "</robot>")
    m2 = model_from_description(swapped, "swapped.urdf")
    assert m2.drive.kind == "skid_steer" and m2.control_beside is not None


@pytest.fixture
def env(tmp_path: Path) -> Iterator[dict[str, str]]:
    base = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    with run_master(env=base) as uri:
        yield dict(base, ROS_MASTER_URI=uri, ROS_PACKAGE_PATH=str(PACKAGES), PYTHONUNBUFFERED="1")


def _echo(env: dict[str, str], topic: str) -> str:
    out = subprocess.run(
        [ninjemys_bin("rostopic"), "echo", "-n", "1", topic],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_joint_state_controller_publishes_the_wheels_while_the_plugin_drives(
    env: dict[str, str], tmp_path: Path
) -> None:
    launch = Launched(
        [ninjemys_bin("roslaunch"), "skid_control_test", "bringup.launch"], env, tmp_path / "launch.log"
    )
    pub = None
    try:
        launch.wait_for("Successfully spawned", timeout=60)
        log = launch.wait_for("Loaded controllers: joint_state_controller", timeout=60)
        assert "couldn't find the expected controller_manager" not in log
        states = _echo(env, "/joint_states")
        for wheel in WHEELS:
            assert f"- {wheel}" in states, states
        pub = subprocess.Popen(
            [ninjemys_bin("rostopic"), "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist", "{linear: {x: 0.2}}"],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        for _ in range(100):  # until the command has reached the plugin (sim time: no wall-clock assertions)
            velocity = _echo(env, "/joint_states/velocity")
            if "[5.0, 5.0, 5.0, 5.0]" in velocity:
                break
        assert "[5.0, 5.0, 5.0, 5.0]" in velocity  # 0.2 m/s on 0.04 m wheels, read by the controller
        assert "x: 0.2" in _echo(env, "/odom/twist/twist/linear")  # the skid steer still drives
    finally:
        if pub is not None:
            pub.terminate()
            pub.wait(20)
        launch.stop()
