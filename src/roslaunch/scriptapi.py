"""roslaunch.scriptapi: ROSLaunch, launching single nodes from a script (``launch(Node(...))``
returns a process with ``is_alive()`` and ``stop()``).

Each launched node runs under a supervisor of its own (ninjemys.launch's, as in a launch file: same
command line, environment, log files, SIGINT/SIGTERM/SIGKILL stop), on its own thread.
"""

from __future__ import annotations

import os
import re
import threading

import rosgraph
import rosgraph.names
from ninjemys.errors import NinjemysError
from ninjemys.launch.launcher import process_specs
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.launch.runner import Supervisor
from ninjemys.roshome import log_directory

from . import rlutil
from .core import Node, RLException
from .parent import ROSLaunchParent, renumber

__all__ = ["ROSLaunch", "NodeProcess"]


class NodeProcess:
    """A node started by ROSLaunch.launch: ``is_alive()``, ``stop()``, ``get_exit_code()``, ``pid``."""

    def __init__(self, name: str, supervisor: Supervisor) -> None:
        self.name = name
        self._supervisor = supervisor
        self._started = threading.Event()
        supervisor.on_event = lambda kind, _name: self._started.set()
        self._thread = threading.Thread(target=supervisor.run, name=f"roslaunch-{name}", daemon=True)
        self._thread.start()
        self._started.wait(30.0)
        popen = supervisor.procs[0].popen
        self.pid = popen.pid if popen is not None else None

    def is_alive(self) -> bool:
        """True while the node's process runs."""
        popen = self._supervisor.procs[0].popen
        return self._thread.is_alive() and popen is not None and popen.poll() is None

    def get_exit_code(self) -> int | None:
        """The process's exit code once it has ended, else None."""
        return self._supervisor.procs[0].exit_code

    def stop(self) -> None:
        """Stop the node (SIGINT, then SIGTERM, then SIGKILL) and wait until it is gone."""
        self._supervisor.request_shutdown()
        self._thread.join()

    def __str__(self) -> str:
        return self.name


def _spec(node: Node) -> NodeSpec:
    name = node.name
    if not name:  # ROS 1 names an unnamed scripted node anonymously after its type
        name = rosgraph.names.anonymous_name(re.sub(r"\W", "_", os.path.splitext(node.type)[0]) or "node")
    return NodeSpec(
        package=node.package,
        type=node.type,
        name=name,
        namespace=node.namespace,
        args=node.args,
        machine_name=node.machine_name,
        respawn=node.respawn,
        respawn_delay=node.respawn_delay,
        required=node.required,
        remap_args=[tuple(r) for r in node.remap_args],  # type: ignore[misc]
        env_args=[tuple(e) for e in node.env_args],  # type: ignore[misc]
        output=node.output,
        cwd="node" if node.cwd == "node" else None,
        launch_prefix=node.launch_prefix,
        filename=node.filename,
    )


class ROSLaunch:
    """Launch nodes from a script: ``start()`` (a master is started if none runs), then
    ``launch(node)`` per node, ``stop()`` at the end."""

    def __init__(self) -> None:
        uuid = rlutil.get_or_generate_uuid(None, True)
        self.parent = ROSLaunchParent(uuid, [], is_core=False)
        self.started = False
        self._processes: list[NodeProcess] = []

    def load(self, f: str) -> None:
        """Add launch file ``f`` to what start() launches (before start(), RLException after)."""
        if self.started:
            raise RLException("ROSLaunch.load: already started; load files before start()")
        self.parent.roslaunch_files = [*self.parent.roslaunch_files, f]

    def load_str(self, s: str) -> None:
        """Add launch XML ``s`` to what start() launches (before start(), RLException after)."""
        if self.started:
            raise RLException("ROSLaunch.load_str: already started; load launch XML before start()")
        self.parent.roslaunch_strs = [*(self.parent.roslaunch_strs or []), s]

    def launch(self, node: Node) -> NodeProcess:
        """Start ``node``; returns its process. RLException before start() or if it cannot start."""
        if not self.started:
            raise RLException("please start ROSLaunch first")
        if not isinstance(node, Node):
            raise ValueError("arg must be of type Node")
        spec = _spec(node)
        env = dict(os.environ)
        uri = rosgraph.get_master_uri()
        env["ROS_MASTER_URI"] = uri
        log_dir = log_directory(env) / self.parent.run_id
        try:
            procs = process_specs(LaunchPlan(nodes=[spec]), self.parent.options, uri, log_dir, env)
        except NinjemysError as exc:
            raise RLException(f"failed to launch {node.package}/{node.type}: {exc}") from None
        if not procs:
            raise RLException(f"failed to launch {node.package}/{node.type}")
        name = renumber(procs[0], spec)
        node.process_name = procs[0].name
        process = NodeProcess(name, Supervisor(procs))
        if process.pid is None:
            raise RLException(f"failed to launch {node.package}/{node.type}")
        self._processes.append(process)
        return process

    def start(self) -> None:
        """Start the launch infrastructure (and a master if none runs)."""
        self.parent.start(auto_terminate=False)
        self.started = True

    def spin(self) -> None:
        """Wait until the launch is shut down."""
        self.parent.spin()

    def spin_once(self) -> None:
        """One round of the parent's loop (see ROSLaunchParent.spin_once)."""
        self.parent.spin_once()

    def stop(self) -> None:
        """Stop every launched node, then the launch (and a master it started)."""
        for process in self._processes:
            process.stop()
        self.parent.shutdown()
