"""roslaunch.core: what ROS 1 scripts build launches from (Node, RLException, run ids)."""

from __future__ import annotations

import re
import sys
import uuid
from collections.abc import Callable
from typing import Any
from xml.sax.saxutils import escape

import rosgraph.names

__all__ = [
    "RLException",
    "Node",
    "generate_run_id",
    "PHASE_SETUP",
    "PHASE_RUN",
    "PHASE_TEARDOWN",
    "TEST_TIME_LIMIT_DEFAULT",
    "printlog",
    "printlog_bold",
    "printerrlog",
    "add_printlog_handler",
    "add_printerrlog_handler",
    "clear_printlog_handlers",
    "clear_printerrlog_handlers",
]

PHASE_SETUP = "setup"
PHASE_RUN = "run"
PHASE_TEARDOWN = "teardown"
#: seconds a <test> may run by default
TEST_TIME_LIMIT_DEFAULT = 60

_printlog_handlers: list[Callable[[str], Any]] = []
_printerrlog_handlers: list[Callable[[str], Any]] = []


def add_printlog_handler(h: Callable[[str], Any]) -> None:
    """Also send what printlog prints to ``h`` (configure_logging adds the roslaunch logger)."""
    _printlog_handlers.append(h)


def add_printerrlog_handler(h: Callable[[str], Any]) -> None:
    """Also send what printerrlog prints to ``h``."""
    _printerrlog_handlers.append(h)


def clear_printlog_handlers() -> None:
    """Forget every printlog handler."""
    del _printlog_handlers[:]


def clear_printerrlog_handlers() -> None:
    """Forget every printerrlog handler."""
    del _printerrlog_handlers[:]


def printlog(msg: str) -> None:
    """Print ``msg`` and hand it to the printlog handlers."""
    for h in _printlog_handlers:
        h(msg)
    print(msg)


def printlog_bold(msg: str) -> None:
    """printlog in bold on a terminal."""
    for h in _printlog_handlers:
        h(msg)
    print(f"\033[1m{msg}\033[0m" if sys.stdout.isatty() else msg)


def printerrlog(msg: str) -> None:
    """Print ``msg`` on stderr (red on a terminal) and hand it to the printerrlog handlers."""
    for h in _printerrlog_handlers:
        h(msg)
    print(f"\033[31m{msg}\033[0m" if sys.stderr.isatty() else msg, file=sys.stderr)


def _xml_escape(s: Any) -> Any:
    return escape(s, entities={'"': "&quot;"}) if isinstance(s, str) else s


class RLException(Exception):
    """A launch failed (unknown file or package, bad node, launch not started ...)."""


def generate_run_id() -> str:
    """A new run id (a UUID, as ROS 1's roscore puts in ``/run_id``)."""
    return str(uuid.uuid1())


class Node:
    """A node to launch (``roslaunch.scriptapi.ROSLaunch.launch``), with ROS 1's attributes and checks."""

    __slots__ = (
        "package",
        "type",
        "name",
        "namespace",
        "machine_name",
        "machine",
        "args",
        "respawn",
        "respawn_delay",
        "remap_args",
        "env_args",
        "process_name",
        "output",
        "cwd",
        "launch_prefix",
        "required",
        "filename",
    )

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
        self.machine: Any = None

    def xmltype(self) -> str:
        """The launch XML tag this is (``node``)."""
        return "node"

    def xmlattrs(self) -> list[tuple[str, Any]]:
        """``(attribute, value)`` of the launch XML tag, None for unset ones."""
        return [
            ("pkg", self.package),
            ("type", self.type),
            ("machine", self.machine_name),
            ("ns", self.namespace),
            ("args", self.args),
            ("output", self.output),
            ("cwd", self.cwd or None),
            ("respawn", self.respawn),
            ("respawn_delay", self.respawn_delay),
            ("name", self.name or None),
            ("launch-prefix", self.launch_prefix),
            ("required", self.required),
        ]

    def _xml(self, keep: Callable[[str], bool]) -> str:
        t = self.xmltype()
        attrs = " ".join(f'{a}="{_xml_escape(v)}"' for a, v in self.xmlattrs() if v is not None and keep(a))
        text = f"<{t} {attrs}>\n"
        text += "".join('  <remap from="{}" to="{}" />\n'.format(*r) for r in self.remap_args)
        text += "".join('  <env name="{}" value="{}" />\n'.format(*e) for e in self.env_args)
        return text + f"</{t}>"

    def to_xml(self) -> str:
        """The node as a launch file ``<node>`` (private parameters cannot be represented)."""
        return self._xml(lambda a: True)

    def to_remote_xml(self) -> str:
        """to_xml without the ``machine`` attribute, as sent to a remote roslaunch."""
        return self._xml(lambda a: a != "machine")
