"""The launch runner's view of the master: is one up, start ours if not, load the plan's parameters.

Kept apart from the process supervisor so the supervisor never knows about XML-RPC, and so the
one place that talks to the master is small enough to read at a glance.
"""

from __future__ import annotations

import subprocess
import time
import uuid
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import yaml

from ninjemys.commands import command_path
from ninjemys.errors import LaunchError, MasterError, NinjemysError
from ninjemys.launch.plan import LaunchPlan
from ninjemys.launch.runner import DEATH_WRAPPER
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import is_local_address

CALLER_ID = "/roslaunch"


def master_uri_for(port: int | None, env: dict[str, str]) -> str:
    """ROS_MASTER_URI, or ``http://localhost:PORT/`` when ``-p PORT`` is given (as roslaunch)."""
    if port:
        return f"http://localhost:{port}/"
    return env.get("ROS_MASTER_URI") or "http://localhost:11311/"


def is_local_uri(uri: str) -> bool:
    return is_local_address(urlsplit(uri).hostname or "")


def is_loopback_uri(uri: str) -> bool:
    """A URI only this machine can use (``localhost``, ``127.x``): useless to a remote node."""
    host = urlsplit(uri).hostname or ""
    return host in ("localhost", "::1", "") or host.startswith("127.")


def master_is_up(uri: str, timeout: float = 1.0) -> bool:
    try:
        MasterClient(uri, CALLER_ID, timeout=timeout).get_pid()
        return True
    except (NinjemysError, OSError):
        return False


def wait_for_master(uri: str, deadline: float | None, proc: subprocess.Popen | None = None) -> bool:
    """Wait until the master answers (short backoff: a port that is not open yet cannot be waited on)."""
    delay = 0.005
    while True:
        if master_is_up(uri, timeout=0.5):
            return True
        if proc is not None and proc.poll() is not None:
            return False
        if deadline is not None and time.monotonic() > deadline:
            return False
        time.sleep(delay)
        delay = min(delay * 2, 0.1)


def start_core(uri: str, log_path: Path, env: dict[str, str]) -> subprocess.Popen:
    """Start our ``roscore`` on the URI's port, its output into ``log_path``; LaunchError if it fails."""
    port = urlsplit(uri).port or 11311
    try:
        roscore = command_path("roscore")
    except FileNotFoundError as exc:
        raise LaunchError(f"cannot auto-start a master: {exc}") from None
    log_path.parent.mkdir(parents=True, exist_ok=True)
    with open(log_path, "ab") as log:
        proc = subprocess.Popen(
            [*DEATH_WRAPPER, roscore, "-p", str(port)],
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            env=env,
            start_new_session=True,
        )
    if not wait_for_master(uri, time.monotonic() + 20.0, proc):
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        tail = log_path.read_text(errors="replace").strip().splitlines()[-3:] if log_path.exists() else []
        raise LaunchError(
            f"the auto-started master on port {port} did not come up: {' / '.join(tail) or 'no output'}"
        )
    return proc


def run_id(client: MasterClient) -> str:
    """The session's /run_id (set by roscore); a fresh one is stored if the master has none."""
    for _ in range(20):
        try:
            if client.has_param("/run_id"):
                return str(client.get_param("/run_id"))
        except MasterError:
            pass
        time.sleep(0.01)
    value = str(uuid.uuid1())
    client.set_param("/run_id", value)
    return value


def _xmlrpc_value(value: Any) -> Any:
    if isinstance(value, bytes):
        import xmlrpc.client

        return xmlrpc.client.Binary(value)
    return value


def load_parameters(client: MasterClient, plan: LaunchPlan) -> None:
    """ROS 1's order: rosparam dump/delete commands, then clear_params, then every parameter."""
    for command in plan.setup_commands:
        if command.command == "delete":
            try:
                client.delete_param(command.param)
            except MasterError:
                pass
        elif command.command == "dump" and command.file:
            value = client.get_param(command.param) if client.has_param(command.param) else {}
            Path(command.file).write_text(yaml.safe_dump(value), encoding="utf-8")
    for ns in plan.clear_params:
        key = ns.rstrip("/") or "/"
        if client.has_param(key):
            client.delete_param(key)
    for key, value in plan.params.items():
        try:
            client.set_param(key, _xmlrpc_value(value))
        except MasterError as exc:
            raise LaunchError(f"cannot set parameter [{key}] on the master: {exc}") from None
