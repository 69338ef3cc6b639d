"""joint_state_controller's shipped configuration: the ROSbot's Gazebo bringup (and course copies of
it) loads ``$(find joint_state_controller)/joint_state_controller.yaml`` and spawns the controller;
Noetic's package installs that file and its launch file, ours stopped the launch at the missing file."""

from __future__ import annotations

import os

from ninjemys.launch.xml import load_launch
from ninjemys.packages.discovery import find_package


def test_joint_state_controller_ships_its_yaml_and_launch_file() -> None:
    share = find_package("joint_state_controller")
    plan = load_launch([share / "joint_state_controller.launch"], env=dict(os.environ))
    assert plan.params["/joint_state_controller/type"] == "joint_state_controller/JointStateController"
    assert plan.params["/joint_state_controller/publish_rate"] == 50
    (spawner,) = plan.nodes
    assert (spawner.package, spawner.type, spawner.name, spawner.args) == (
        "controller_manager",
        "spawner",
        "joint_state_controller_spawner",
        "joint_state_controller",
    )
    # the bringup pattern: the yaml loaded by a launch file of the user's own package
    text = (
        '<launch><rosparam command="load" file="$(find joint_state_controller)/joint_state_controller.yaml"/>'
        "</launch>"
    )
    assert (
        load_launch([], env=dict(os.environ), xml_text=text).params["/joint_state_controller/publish_rate"]
        == 50
    )
