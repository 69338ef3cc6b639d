"""``joint_state_publisher_gui``: joint_state_publisher with a slider per free joint, as a page.

The command runs, in one process, the joint_state_publisher node (named ``joint_state_publisher_gui``
as in ROS 1, with every parameter of :mod:`ninjemys.robot.joint_state_publisher`), the gateway on
that node and the web app serving ``/joint_state_publisher_gui``. The page reads the robot
description through the gateway (a parameter read), draws a slider per free joint (mimic joints
follow theirs) and publishes its values as a ``sensor_msgs/JointState`` on the node's private
``~slider_input`` topic, which the node takes as one more source; so the page has no data path but
the gateway, as rviz and rqt. Difference from ROS 1: that private topic is visible on the graph.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any
from urllib.parse import urlencode

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.errors import NinjemysError
from ninjemys.node.run import start_node
from ninjemys.robot.joint_state_publisher import start
from ninjemys.serve.http import Response
from ninjemys.web.app import STATIC_DIR, WebApp
from ninjemys.web.browser import serve_until_stopped, stop_signals

PAGE = "/joint_state_publisher_gui"


class JointStatePublisherGui:
    """The node, its joint_state_publisher, the gateway and the page; ``start()`` returns the URL."""

    def __init__(self, node: Any, host: str = "127.0.0.1", port: int = 0) -> None:
        self.node = node
        self.input = node.resolve_name("~slider_input")
        self.description = node.resolve_name("robot_description")
        code = start(node, (self.input,))
        if code:
            raise NinjemysError("joint_state_publisher_gui: robot_description is missing or malformed")
        self.gateway = Gateway(GatewayOptions(node_name=node.name, update_period=0.5), node=node)
        self.gateway.start()
        self.app = WebApp(node.master_uri, caller_id=node.name, host=host, port=port)
        self.app.add_gateway(self.gateway, "/ws")
        self.app.add_page("Joint State Publisher", PAGE)
        self.app.server.route(
            "GET",
            PAGE,
            lambda _r: Response((STATIC_DIR / "jsp_gui.html").read_bytes(), 200, "text/html; charset=utf-8"),
        )

    def start(self) -> str:
        base = self.app.start()
        query = urlencode(
            [("description", self.description), ("input", self.input), ("ns", self.node.name + "/")]
        )
        return f"{base}{PAGE.lstrip('/')}?{query}"

    def stop(self) -> None:
        self.gateway.shutdown()
        self.app.stop()
        self.node.shutdown("joint_state_publisher_gui closed")


def main(argv: list[str] | None = None) -> int:
    """``rosrun joint_state_publisher_gui joint_state_publisher_gui`` (ROS arguments as rosrun's)."""
    argv = sys.argv[1:] if argv is None else argv
    p = argparse.ArgumentParser(prog="joint_state_publisher_gui", description=__doc__.splitlines()[0])
    p.add_argument(
        "--port", type=int, default=int(os.environ.get("NINJEMYS_WEB_PORT", "0")), help="HTTP port"
    )
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the URL")
    args, _ros = p.parse_known_args([a for a in argv if ":=" not in a])
    ros_args = [a for a in argv if ":=" in a]
    try:
        node = start_node("joint_state_publisher_gui", ros_args)
    except NinjemysError as exc:
        print(f"joint_state_publisher_gui: {exc}", file=sys.stderr)
        return 1
    try:
        gui = JointStatePublisherGui(node, args.host, args.port)
    except NinjemysError as exc:
        node.shutdown("exit")
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    stopped = stop_signals()
    try:
        url = gui.start()
    except OSError as exc:
        gui.stop()
        print(f"ERROR: cannot serve on {args.host}:{args.port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(f"joint_state_publisher_gui: {url}", flush=True)
    return serve_until_stopped(url, not args.no_browser, gui.stop, stopped)
