"""roslaunch.core: what ROS 1 scripts build launches from (Node, RLException, run ids)."""

from __future__ import annotations

import re
import uuid

import rosgraph.names

__all__ = ["RLException", "Node", "generate_run_id"]


class RLException(Exception):
    """A launch failed (unknown file or package, bad node, launch not started ...)."""


def generate_run_id() -> str:
    """A new run id (a UUID, as ROS 1's roscore puts in ``/run_id``)."""
    return str(uuid.uuid1())


class Node:
    """A node to launch (``roslaunch.scriptapi.ROSLaunch.launch``), with ROS 1's attributes and checks."""

    def __init__(
        self,
        package: str,
        node_type: str,
        name: str | None = None,
        namespace: str = "/",
        machine_name: str | None = None,
        args: str = "",
        respawn: bool = False,
        respawn_delay: float = 0.0,
        remap_args: list[tuple[str, str]] | None = None,
        env_args: list[tuple[str, str]] | None = None,
        output: str | None = None,
        cwd: str | None = None,
        launch_prefix: str | None = None,
        required: bool = False,
        filename: str = "<unknown>",
    ) -> None:
        self.package = package
        self.type = node_type
        self.name = name or None
        self.namespace = re.sub("//+", "/", rosgraph.names.make_global_ns(namespace or "/"))
        self.machine_name = machine_name or None
        self.respawn = respawn
        self.respawn_delay = respawn_delay
        self.args = args or ""
        self.remap_args = remap_args or []
        self.env_args = env_args or []
        self.output = output
        self.cwd = "ROS_HOME" if cwd == "ros_home" else cwd
        self.launch_prefix = launch_prefix or None
        self.required = required
        self.filename = filename
        if self.respawn and self.required:
            raise ValueError("respawn and required cannot both be set to true")
        if self.name and rosgraph.names.SEP in self.name:
            raise ValueError("node name cannot contain a namespace")
        if not self.package.strip():
            raise ValueError("package must be non-empty")
        if not self.type.strip():
            raise ValueError("type must be non-empty")
        if self.output not in ("log", "screen", None):
            raise ValueError("output must be one of 'log', 'screen'")
        if self.cwd not in ("ROS_HOME", "node", None):
            raise ValueError("cwd must be one of 'ROS_HOME', 'node'")
        #: the process name once launched (``name-N``), as ROS 1 records it
        self.process_name: str | None = None
        self.machine = None
