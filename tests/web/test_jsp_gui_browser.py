"""joint_state_publisher_gui's page in headless Chromium: one slider per free joint of the URDF on
the parameter server (mimic, ``~dependent_joints`` and fixed joints get none; ``~zeros`` set where they start), and moving a slider changes
/joint_states, mimic and dependent joints included."""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import xmlrpc.client
from typing import Any

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import free_port, ninjemys_bin, run_master, wait_until

pytestmark = pytest.mark.browser

URDF = """<robot name="arm">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="e"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="a"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <limit lower="0.1" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="finger" type="revolute"><parent link="b"/><child link="c"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="shoulder" multiplier="2" offset="0.1"/></joint>
  <joint name="bolt" type="fixed"><parent link="c"/><child link="d"/></joint>
  <joint name="wrist" type="revolute"><parent link="d"/><child link="e"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>"""


def test_slider_moves_joint_states(browser_page: Any) -> None:
    with run_master() as uri:
        master = xmlrpc.client.ServerProxy(uri)
        master.setParam("/test", "/robot_description", URDF)
        master.setParam("/test", "/joint_state_publisher_gui/zeros", {"slide": 0.2})
        dependent = {"wrist": {"parent": "shoulder", "factor": -1.0}}
        master.setParam("/test", "/joint_state_publisher_gui/dependent_joints", dependent)
        proc = subprocess.Popen(
            [ninjemys_bin("rosrun"), "joint_state_publisher_gui", "joint_state_publisher_gui"]
            + ["--no-browser", "--port", str(free_port())],
            env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        node = Node("jsp_gui_test", anonymous=True, master_uri=uri)
        try:
            assert proc.stdout is not None
            line = proc.stdout.readline().strip()
            assert line.startswith("joint_state_publisher_gui: http://"), line
            url = line.split(": ", 1)[1]
            last: dict[str, float] = {}
            lock = threading.Lock()

            def on_state(msg: Any) -> None:
                with lock:
                    last.update(zip(msg.name, msg.position, strict=True))

            node.subscriber("/joint_states", get_message_class("sensor_msgs/JointState"), on_state)
            wait_until(lambda: len(last) == 4, 30, "joint_states from the GUI node")
            assert last["shoulder"] == 0.0 and abs(last["slide"] - 0.2) < 1e-9
            page = browser_page
            page.goto(url)
            page.wait_for_function("window.jspGui && window.jspGui.ready", timeout=30000)
            names = page.eval_on_selector_all("input[type=range]", "els => els.map(e => e.dataset.joint)")
            assert names == ["shoulder", "slide"]
            page.eval_on_selector(
                "input[data-joint=shoulder]",
                "el => { el.value = '0.75'; el.dispatchEvent(new Event('input')); }",
            )

            def moved() -> bool:
                with lock:
                    return abs(last.get("shoulder", 0) - 0.75) < 1e-6

            wait_until(moved, 30, "shoulder at 0.75 on /joint_states")
            with lock:
                assert abs(last["finger"] - (2 * 0.75 + 0.1)) < 1e-9
                assert abs(last["slide"] - 0.2) < 1e-9
                assert abs(last["wrist"] + 0.75) < 1e-9
            assert page.eval_on_selector("input[data-joint=slide]", "el => Number(el.value)") == 0.2
        finally:
            node.shutdown("test done")
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
