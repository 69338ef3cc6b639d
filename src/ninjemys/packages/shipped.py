"""Executables that ship inside ninjemys as Python modules, by ROS package name.

``rosrun turtlesim turtlesim_node`` and ``<node pkg="turtlesim" type="turtlesim_node"/>`` have no
file to execute: the node is ``ninjemys.web.turtlesim_view:main``. This table maps
package -> executable -> :class:`ShippedExecutable`; :mod:`ninjemys.packages.run_shipped` is the
process entry point that imports the module and calls the function with the user's arguments.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class ShippedExecutable:
    """``target`` is ``"module:function"``; ``prefix_args`` go before the user's arguments."""

    package: str
    name: str
    target: str
    prefix_args: tuple[str, ...] = ()

    @property
    def module(self) -> str:
        return self.target.split(":", 1)[0]

    @property
    def function(self) -> str:
        return self.target.split(":", 1)[1]

    def command(self, args: list[str] | tuple[str, ...] = ()) -> list[str]:
        """The argv that runs this executable in a fresh interpreter (the one ninjemys runs in)."""
        return [sys.executable, "-m", "ninjemys.packages.run_shipped", self.package, self.name, *args]


def _table() -> dict[str, dict[str, ShippedExecutable]]:
    entries: dict[str, dict[str, tuple[str, tuple[str, ...]]]] = {
        "turtlesim": {
            "turtlesim_node": ("ninjemys.web.turtlesim_view:main", ()),
            "turtle_teleop_key": ("ninjemys.sim.teleop_key:main", ()),
            "draw_square": ("ninjemys.sim.draw_square:main", ()),
            "mimic": ("ninjemys.sim.mimic:main", ()),
        },
        "rqt_graph": {"rqt_graph": ("ninjemys.web.rqt_graph:main", ())},
        "smach_viewer": {"smach_viewer.py": ("ninjemys.web.smach_viewer:main", ())},
        "rostest": {
            "hztest": ("ninjemys.tools.hztest:main", ()),
            "publishtest": ("ninjemys.tools.rostest_nodes:publishtest_main", ()),
            "paramtest": ("ninjemys.tools.rostest_nodes:paramtest_main", ()),
            "advertisetest": ("ninjemys.tools.rostest_nodes:advertisetest_main", ()),
        },
        "rviz": {"rviz": ("ninjemys.web.rviz:main", ())},
        "rqt_gui": {"rqt_gui": ("ninjemys.web.rqt:rqt_main", ())},
        "rqt_plot": {"rqt_plot": ("ninjemys.web.rqt:plot_main", ())},
        "rqt_console": {"rqt_console": ("ninjemys.web.rqt:console_plugin_main", ())},
        "rqt_logger_level": {"rqt_logger_level": ("ninjemys.web.rqt:logger_level_main", ())},
        "rqt_bag": {"rqt_bag": ("ninjemys.web.rqt:bag_main", ())},
        "rqt_image_view": {"rqt_image_view": ("ninjemys.web.rqt:image_view_main", ())},
        "rqt_tf_tree": {"rqt_tf_tree": ("ninjemys.web.rqt:tf_tree_main", ())},
        "rqt_reconfigure": {"rqt_reconfigure": ("ninjemys.web.rqt:reconfigure_main", ())},
        "rqt_topic": {"rqt_topic": ("ninjemys.web.rqt:topic_main", ())},
        "rqt_publisher": {"rqt_publisher": ("ninjemys.web.rqt:publisher_main", ())},
        "rqt_service_caller": {"rqt_service_caller": ("ninjemys.web.rqt:service_caller_main", ())},
        "actionlib": {"axclient.py": ("ninjemys.web.rqt:axclient_main", ())},
        "puzzlebot_sim": {
            "sim_node": ("ninjemys.web.puzzlebot_view:main", ()),
            "world_to_map": ("ninjemys.sim.world_to_map:main", ()),
        },
        # -- Gazebo's names (docs/sim.md, "Gazebo's names") --
        "gazebo_ros": {
            "gzserver": ("ninjemys.web.gazebo_ros:gzserver_main", ()),
            "gzclient": ("ninjemys.web.gazebo_ros:gzclient_main", ()),
            "gazebo": ("ninjemys.web.gazebo_ros:gazebo_main", ()),
            "debug": ("ninjemys.web.gazebo_ros:gzserver_main", ()),
            "spawn_model": ("ninjemys.sim.spawn_model:main", ()),
        },
        "teleop_twist_keyboard": {
            "teleop_twist_keyboard.py": ("ninjemys.sim.teleop_twist_keyboard:main", ()),
        },
        "map_server": {
            "map_server": ("ninjemys.nav.map_server_node:main", ()),
            "map_saver": ("ninjemys.nav.map_server_node:saver_main", ()),
        },
        "amcl": {"amcl": ("ninjemys.nav.amcl_node:main", ())},
        "move_base": {"move_base": ("ninjemys.nav.move_base_node:main", ())},
        "gmapping": {"slam_gmapping": ("ninjemys.nav.slam_node:main", ())},
        "puzzlebot_safety": {"safety_monitor": ("ninjemys.nav.safety_node:main", ())},
        "rospy_tutorials": {
            name: (f"ninjemys.tutorials.{name.removesuffix('.py')}:main", ())
            for name in (
                "talker",
                "talker.py",
                "listener",
                "listener.py",
                "add_two_ints_server",
                "add_two_ints_client",
            )
        },
        "rosout": {"rosout": ("ninjemys.tools.rosout:main", ())},
        "rosbridge_server": {"rosbridge_websocket": ("ninjemys.bridge.main:rosbridge_main", ())},
        "foxglove_bridge": {"foxglove_bridge": ("ninjemys.bridge.main:foxglove_main", ())},
        "rosapi": {"rosapi_node": ("ninjemys.bridge.rosapi:main", ())},
        "tf2_web_republisher": {"tf2_web_republisher": ("ninjemys.bridge.tf_republisher:main", ())},
        "dynamic_reconfigure": {"dynparam": ("ninjemys.tools.dynparam:main", ())},
        "actionlib_tutorials": {
            "fibonacci_server": ("ninjemys.tutorials.actionlib.fibonacci_server:main", ()),
            "fibonacci_server.py": ("ninjemys.tutorials.actionlib.fibonacci_server:main", ()),
            "fibonacci_client": ("ninjemys.tutorials.actionlib.fibonacci_client:main", ()),
            "fibonacci_client.py": ("ninjemys.tutorials.actionlib.fibonacci_client:main_py", ()),
            "averaging_server": ("ninjemys.tutorials.actionlib.averaging_server:main", ()),
            "averaging_client": ("ninjemys.tutorials.actionlib.averaging_client:main", ()),
            "gen_numbers.py": ("ninjemys.tutorials.actionlib.gen_numbers:main", ()),
        },
        "tf2_ros": {
            "static_transform_publisher": ("ninjemys.tools.static_transform_publisher:main", ()),
            "buffer_server": ("ninjemys.tools.buffer_server:main", ()),
        },
        "tf": {
            "tf_echo": ("ninjemys.tools.tf_echo:main", ()),
            "tf_monitor": ("ninjemys.tools.tf_monitor:main", ()),
            "static_transform_publisher": ("ninjemys.tools.static_transform_publisher:tf_main", ()),
            "view_frames": ("ninjemys.tools.view_frames:tf_main", ()),
        },
        "tf2_tools": {"view_frames.py": ("ninjemys.tools.view_frames:main", ())},
        "image_transport": {"republish": ("ninjemys.image_transport.republish:main", ())},
        "robot_state_publisher": {
            "robot_state_publisher": ("ninjemys.robot.state_publisher:main", ()),
            "state_publisher": ("ninjemys.robot.state_publisher:legacy_main", ()),
        },
        "joint_state_publisher": {
            "joint_state_publisher": ("ninjemys.robot.joint_state_publisher:main", ()),
        },
        "joint_state_publisher_gui": {
            "joint_state_publisher_gui": ("ninjemys.web.jsp_gui:main", ()),
        },
        # -- drivers (docs/drivers.md) --
        "joy": {"joy_node": ("ninjemys.drivers.joy_node:main", ())},
        "teleop_twist_joy": {"teleop_node": ("ninjemys.drivers.teleop_twist_joy:main", ())},
        "realsense2_camera": {"realsense2_camera_node": ("ninjemys.drivers.realsense_node:main", ())},
        "image_proc": {"image_proc": ("ninjemys.drivers.rgbd_proc:image_proc_main", ())},
        "depth_image_proc": {
            "point_cloud_xyzrgb": ("ninjemys.drivers.rgbd_proc:point_cloud_xyzrgb_main", ())
        },
        "rosserial_python": {
            "serial_node.py": ("ninjemys.drivers.rosserial_node:main", ()),
            "message_info_service.py": ("ninjemys.drivers.rosserial_node:message_info_main", ()),
        },
        "rosserial_arduino": {"serial_node.py": ("ninjemys.drivers.rosserial_node:arduino_main", ())},
        "rosserial_server": {
            "serial_node": ("ninjemys.drivers.rosserial_node:server_serial_main", ()),
            "socket_node": ("ninjemys.drivers.rosserial_node:socket_main", ()),
        },
        "rplidar_ros": {
            "rplidarNode": ("ninjemys.drivers.rplidar_node:main", ()),
            "create_udev_rules.sh": ("ninjemys.drivers.udev_rules:create_main", ()),
            "delete_udev_rules.sh": ("ninjemys.drivers.udev_rules:delete_main", ()),
        },
        # -- ros_control (docs/sim.md): the manager runs inside the simulator --
        "controller_manager": {
            "spawner": ("ninjemys.sim.ros_control.spawner:main", ()),
            "unspawner": ("ninjemys.sim.ros_control.spawner:unspawner_main", ()),
            "controller_manager": ("ninjemys.sim.ros_control.cm_command:main", ()),
        },
        "xacro": {
            "xacro": ("ninjemys.tools.xacro:main", ()),
            "xacro.py": ("ninjemys.tools.xacro:main", ()),
        },
        # -- roslint (REAL4): the linters roslint_cpp()/roslint_python() run, ROS style rules --
        "roslint": {
            "cpplint": ("ninjemys.tools.roslint:main", ("cpplint",)),
            "pep8": ("ninjemys.tools.roslint:main", ("pep8",)),
        },
        "rosbag": {
            sub: ("ninjemys.tools.rosbag:main", (sub,))
            for sub in (
                "record",
                "play",
                "info",
                "check",
                "fix",
                "filter",
                "compress",
                "decompress",
                "reindex",
            )
        },
    }
    return {
        pkg: {name: ShippedExecutable(pkg, name, target, prefix) for name, (target, prefix) in exes.items()}
        for pkg, exes in entries.items()
    }


SHIPPED: dict[str, dict[str, ShippedExecutable]] = _table()


def shipped_executable(package: str, name: str) -> ShippedExecutable | None:
    """The shipped executable ``name`` of ``package``, or None."""
    return SHIPPED.get(package, {}).get(name)
