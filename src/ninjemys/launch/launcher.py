"""One roslaunch session: plan -> master (found or auto-started) -> parameters -> supervised nodes.

Everything that can fail because of user input (unknown package or executable, unknown machine,
unreachable ssh host) is checked before the first process starts, so a bad launch file starts
nothing.
"""

from __future__ import annotations

import os
import shlex
import signal
import socket
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ninjemys.errors import LaunchError, NinjemysError
from ninjemys.launch import master_link
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.launch.queries import node_command, node_environment, node_executable
from ninjemys.launch.runner import (
    DEFAULT_SIGINT_TIMEOUT,
    DEFAULT_SIGTERM_TIMEOUT,
    ProcessSpec,
    Supervisor,
    node_process_name,
    remote_command,
)
from ninjemys.master.client import MasterClient
from ninjemys.packages.discovery import PackageIndex, package_path_dirs, underlay_dirs
from ninjemys.packages.executables import find_executable
from ninjemys.roshome import log_directory

if TYPE_CHECKING:
    import subprocess
    from typing import Any

#: what ROS 1's roslaunch prints when nothing is left to run (a launch file of parameters only, or
#: whose every node could not be launched), before it exits 0
NO_PROCESSES = "No processes to monitor\nshutting down processing monitor...\n... shutting down processing monitor complete"


@dataclass
class LaunchOptions:
    screen: bool = False
    log: bool = False
    port: int | None = None
    wait: bool = False
    required: bool = False
    local_only: bool = False
    no_summary: bool = False
    sigint_timeout: float = DEFAULT_SIGINT_TIMEOUT
    sigterm_timeout: float = DEFAULT_SIGTERM_TIMEOUT
    core_only: bool = False
    #: print node output line by line behind ``[name] `` instead of passing it through (ROS 1)
    prefix_output: bool = False


def _strip(value: object) -> str:
    text = str(value)
    if len(text) > 20:
        text = text[:17] + "..."
    return text if all(31 < ord(c) < 127 for c in text) else "<...>"


def summary(plan: LaunchPlan, extra_params: dict[str, object]) -> str:
    """ROS 1's SUMMARY block."""
    out = ["", "SUMMARY", "========"]
    if plan.clear_params:
        out += ["", "CLEAR PARAMETERS", *sorted(f" * {p}" for p in plan.clear_params)]
    params = {**extra_params, **plan.params}
    if params:
        out += ["", "PARAMETERS", *sorted(f" * {k}: {_strip(v)}" for k, v in params.items())]
    machines = sorted(k for k in plan.machines if k)
    if machines:
        out += ["", "MACHINES", *(f" * {m}" for m in machines)]
    out += ["", "NODES"]
    by_ns: dict[str, list[NodeSpec]] = {}
    for node in plan.nodes:
        by_ns.setdefault(node.namespace, []).append(node)
    for ns in sorted(by_ns):
        out.append(f"  {ns}")
        out += sorted(f"    {n.name} ({n.package}/{n.type})" for n in by_ns[ns])
    return "\n".join(out) + "\n"


def _process_specs(
    plan: LaunchPlan,
    opts: LaunchOptions,
    master_uri: str,
    log_dir: Path,
    env: dict[str, str],
    failures: list[str] | None = None,
) -> list[ProcessSpec]:
    """The processes to start. With ``failures``, a local node whose package or executable cannot
    be found is left out and its ROS 1 line goes there (the others still start, as in ROS 1)."""
    index = PackageIndex.from_environment(env)
    specs = []
    ros_home = env.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    counter = 0
    for node in plan.nodes:
        machine = plan.machines.get(node.machine_name or "")
        if machine is None:
            raise LaunchError(
                f"{node.filename}: node [{node.resolved_name}]: unknown machine [{node.machine_name}]"
            )
        local = machine.is_local
        if opts.local_only and not local:
            continue
        if local and failures is not None:
            reason = launch_failure(node, index, env)
            if reason is not None:
                failures.append(f"ERROR: cannot launch node of type [{node.package}/{node.type}]: {reason}")
                continue
        counter += 1
        name = node_process_name(node, counter)
        proc_env = node_environment(node, master_uri, env)
        if opts.prefix_output:  # lines are cut from the pipe as they come; passed through, as in ROS 1
            proc_env["PYTHONUNBUFFERED"] = "1"
        for key, value in machine.env_args:
            proc_env[key] = value
        if local:
            argv = node_command(node, index) + [f"__log:={log_dir / (name + '.log')}"]
            cwd: str | None = ros_home
            if node.cwd == "node":
                exe = node_executable(node, index)
                cwd = str(exe.path.parent) if exe.path is not None else ros_home
        else:
            if master_link.is_loopback_uri(master_uri):
                raise LaunchError(
                    f"machine [{machine.name}] ({machine.address}) cannot reach a master at {master_uri}: "
                    "set ROS_MASTER_URI to this machine's name or address to launch remote nodes"
                )
            # the remote machine runs its own ninjemys: rosrun there finds the package and executable
            # what the launch decides travels (master, namespace, <env>s); the remote machine's own
            # set-up (ROS_IP, ROS_HOSTNAME, ROS_PACKAGE_PATH...) comes from its env-loader, as in ROS 1:
            # this machine's ROS_IP there would advertise the wrong address
            remote_env = {"ROS_MASTER_URI": master_uri, **dict(node.env_args), **dict(machine.env_args)}
            if "ROS_NAMESPACE" in proc_env:
                remote_env["ROS_NAMESPACE"] = proc_env["ROS_NAMESPACE"]
            if "PYTHONUNBUFFERED" in proc_env:
                remote_env["PYTHONUNBUFFERED"] = proc_env["PYTHONUNBUFFERED"]
            argv = remote_command(machine, ["rosrun", node.package, node.type, *_user_args(node)], remote_env)
            cwd = None
        Path(ros_home).mkdir(parents=True, exist_ok=True)
        output = "screen" if opts.screen else "log" if opts.log else (node.output or "log")
        specs.append(
            ProcessSpec(
                name=name,
                argv=argv,
                env=proc_env,
                cwd=cwd,
                output=output,
                respawn=node.respawn,
                respawn_delay=node.respawn_delay,
                required=node.required or opts.required,
                sigint_timeout=node.sigint_timeout
                if node.sigint_timeout is not None
                else opts.sigint_timeout,
                sigterm_timeout=opts.sigterm_timeout,
                log_dir=log_dir,
            )
        )
    return specs


def launch_failure(node: NodeSpec, index: PackageIndex, env: Mapping[str, str]) -> str | None:
    """Why ROS 1's roslaunch could not start ``node`` (its words), or None when it can."""
    try:
        manifest = index.find(node.package)
    except NinjemysError:
        paths = [*package_path_dirs(env), *underlay_dirs()]
        return node.package + "".join(f"\nROS path [{i}]={path}" for i, path in enumerate(paths))
    try:
        find_executable(manifest, node.type)
    except NinjemysError:
        return (
            f"Cannot locate node of type [{node.type}] in package [{node.package}]. Make sure file exists in "
            "package path and permission is set to executable (chmod +x)"
        )
    return None


def process_specs(
    plan: LaunchPlan, opts: LaunchOptions, master_uri: str, log_dir: Path, env: dict[str, str]
) -> list[ProcessSpec]:
    """The processes ``plan``'s nodes run as (command, environment, output, respawn ...), for callers
    that supervise nodes one at a time (the roslaunch.scriptapi facade) instead of a whole session."""
    return _process_specs(plan, opts, master_uri, log_dir, env)


def _user_args(node: NodeSpec) -> list[str]:
    return shlex.split(node.args) + [f"{a}:={b}" for a, b in node.remap_args] + [f"__name:={node.name}"]


class LaunchSession:
    """Runs a plan; ``run()`` blocks until the launch ends and returns its exit status."""

    def __init__(self, plan: LaunchPlan, opts: LaunchOptions, env: dict[str, str] | None = None) -> None:
        self.plan = plan
        self.opts = opts
        self.env = dict(os.environ if env is None else env)
        self.supervisor: Supervisor | None = None
        self._core: subprocess.Popen[Any] | None = None

    def _say(self, text: str) -> None:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()

    def run(self) -> int:
        for warning in self.plan.warnings:
            print(f"WARNING: {warning}", file=sys.stderr)
        uri = master_link.master_uri_for(self.opts.port, self.env)
        self.env["ROS_MASTER_URI"] = uri
        log_root = log_directory(self.env)
        # validate everything user-provided before starting anything
        probe_specs = _process_specs(self.plan, self.opts, uri, log_root / "pending", self.env, [])
        del probe_specs
        try:
            return self._run_with_master(uri, log_root)
        finally:
            if self._core is not None and self._core.poll() is None:
                self._core.kill()
                self._core.wait()

    def _run_with_master(self, uri: str, log_root: Path) -> int:
        core_proc = None
        if not master_link.master_is_up(uri):
            if self.opts.wait:
                self._say(f"waiting for master at {uri} ...")
                master_link.wait_for_master(uri, None)
            elif not master_link.is_local_uri(uri):
                raise LaunchError(
                    f"unable to contact ROS master at [{uri}] (not this machine: cannot auto-start it)"
                )
            else:
                self._say("auto-starting new master")
                core_proc = master_link.start_core(uri, log_root / "latest-master.log", self.env)
                self._core = core_proc
                self._say(f"process[master]: started with pid [{core_proc.pid}]")
        self._say(f"ROS_MASTER_URI={uri}")
        client = MasterClient(uri, master_link.CALLER_ID)
        run_id = master_link.run_id(client)
        log_dir = log_root / run_id
        log_dir.mkdir(parents=True, exist_ok=True)
        launch_log = log_dir / f"roslaunch-{socket.gethostname()}-{os.getpid()}.log"
        self._say(f"... logging to {launch_log}")
        if not self.opts.no_summary:
            self._say(summary(self.plan, {}))
        master_link.load_parameters(client, self.plan)
        client.close()
        failures: list[str] = []
        specs = _process_specs(self.plan, self.opts, uri, log_dir, self.env, failures)
        for line in failures:
            print(line, file=sys.stderr, flush=True)
        if core_proc is not None:
            core_args: Any = core_proc.args  # the argv list start_core passed to Popen
            specs.insert(
                0,
                ProcessSpec(
                    name="master",
                    argv=[str(a) for a in core_args],
                    env=self.env,
                    popen=core_proc,
                    is_core=True,
                    sigint_timeout=self.opts.sigint_timeout,
                ),
            )
        with open(launch_log, "a", encoding="utf-8") as log_file:

            def log(text: str) -> None:
                log_file.write(f"[{time.strftime('%Y-%m-%d %H:%M:%S')}] {text}")
                log_file.flush()

            log(f"roslaunch pid {os.getpid()}, master {uri}, run_id {run_id}, files {self.plan.files}\n")
            return self._supervise(specs, log)

    def _supervise(self, specs: list[ProcessSpec], log: Callable[[str], None]) -> int:
        self.supervisor = Supervisor(specs, log=log, prefix_output=self.opts.prefix_output)
        previous = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
        for sig in previous:
            signal.signal(sig, lambda *_: self.supervisor.request_shutdown() if self.supervisor else None)
        try:
            if not specs:
                self._say(NO_PROCESSES)
                return 0
            return self.supervisor.run()
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
