"""examples/puzzlebot_hw: one launch file brings up the real PuzzleBot's drivers and the nodes around
them, here against emulated devices all at once: the Arduino motor board (rosserial on a pty), an
RPLIDAR A1 (a pty), a game controller (a FIFO) and the RealSense (a recording)."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from ninjemys import testing
from ninjemys.drivers.joystick import JS_EVENT_AXIS, JS_EVENT_BUTTON, JoyEvent
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node

from .conftest import Collect
from .emu_arduino import EmulatedArduino
from .emu_rplidar import EmulatedA1

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "puzzlebot_hw"
TOPICS = {
    "/wl": "std_msgs/Float32",
    "/scan": "sensor_msgs/LaserScan",
    "/joy": "sensor_msgs/Joy",
    "/odom": "nav_msgs/Odometry",
    "/cmd_vel": "geometry_msgs/Twist",
    "/camera/color/image_raw": "sensor_msgs/Image",
}
NODES = ("/motor_board", "/wheel_odometry", "/rplidar", "/camera/realsense2_camera", "/joy_node",
         "/teleop_twist_joy", "/robot_state_publisher", "/map_server", "/amcl", "/move_base")  # fmt: skip


def test_the_hardware_launch_file_starts_every_node_against_the_emulators(tmp_path: Path) -> None:
    fifo = tmp_path / "js0"
    os.mkfifo(fifo)
    js = os.open(fifo, os.O_RDWR | os.O_NONBLOCK)
    board, lidar = EmulatedArduino(rate_hz=20.0), EmulatedA1()
    recording = ""
    try:
        import pyrealsense2  # noqa: F401

        from .realsense_recording import write_recording

        recording = str(write_recording(tmp_path / "camera", frames=300))
    except ImportError:
        pass
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_LOG_DIR=str(tmp_path))
    env["ROS_PACKAGE_PATH"] = os.pathsep.join(p for p in (str(EXAMPLE), env.get("ROS_PACKAGE_PATH", "")) if p)
    try:
        with testing.run_master(env=env) as uri:
            env["ROS_MASTER_URI"] = uri
            node = Node("hw_test", master_uri=uri)
            got = {topic: Collect() for topic in TOPICS}
            for topic, type_name in TOPICS.items():
                node.subscriber(topic, get_message_class(type_name), got[topic])
            launch = subprocess.Popen(
                [testing.ninjemys_bin("roslaunch"), "puzzlebot_hw", "puzzlebot_hw.launch",
                 f"arduino_port:={board.path}", f"lidar_port:={lidar.path}", f"joy_dev:={fifo}",
                 f"camera:={'true' if recording else 'false'}", f"camera_recording:={recording}",
                 "navigation:=true"],
                env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
            )  # fmt: skip
            try:
                board.wait(lambda: board.configured and board.wheel_radius is not None, timeout=60)
                assert board.wheel_radius == pytest.approx(0.05)  # asked of the host, from the launch file
                got["/wl"].wait_for(lambda m: True, timeout=30)
                scan = got["/scan"].wait_for(lambda m: True, timeout=60)
                assert scan.header.frame_id == "laser" and len(scan.ranges) == 360
                got["/odom"].wait_for(lambda m: True, timeout=30)
                if recording:
                    got["/camera/color/image_raw"].wait_for(lambda m: m.encoding == "rgb8", timeout=60)
                # the controller drives the board: xbox enable button (2) held, stick pushed up
                deadline = time.monotonic() + 30
                while not any(c.linear.x > 0.5 for c in board.cmd_vels) and time.monotonic() < deadline:
                    os.write(
                        js,
                        JoyEvent(0, 1, JS_EVENT_BUTTON, 2).pack()
                        + JoyEvent(0, -32767, JS_EVENT_AXIS, 1).pack(),
                    )
                    time.sleep(0.3)
                assert any(c.linear.x > 0.5 for c in board.cmd_vels), board.cmd_vels[-3:]
                state = node.master.get_system_state()
                running = {n for group in state for _, nodes in group for n in nodes}
                missing = [n for n in NODES if n not in running and (recording or "camera" not in n)]
                assert not missing, missing
            finally:
                os.killpg(launch.pid, signal.SIGINT)
                try:
                    out, _ = launch.communicate(timeout=30)
                except subprocess.TimeoutExpired:
                    testing.kill_tree(launch)
                    out, _ = launch.communicate()
                node.shutdown()
            assert "process has died" not in out, out[-3000:]
    finally:
        os.close(js)
        board.close()
        lidar.close()
