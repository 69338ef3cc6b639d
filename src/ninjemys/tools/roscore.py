"""``roscore``: the master, the parameter server and the rosout node, in one fast-starting process.

The master serves on the main thread's event loop from the moment the port is bound; rosout (a node
of the ninjemys runtime) is started next to it on a helper thread, so ``getSystemState`` answers before
rosout has even been imported. Ctrl-C (or SIGTERM, or a ``shutdown`` call) stops both at once.

Port: ``-p PORT``, else the port of ROS_MASTER_URI, else 11311. The URI advertised uses ROS_HOSTNAME /
ROS_IP / the host name. Logs go to ``$ROS_LOG_DIR`` or ``$ROS_HOME/log`` (``~/.ros/log``), in a
directory named after the run id, with a ``latest`` link, as roslaunch does.
"""

from __future__ import annotations

import argparse
import asyncio
import errno
import logging
import os
import signal
import socket
import sys
import threading
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ninjemys import ROS_DISTRO, ROS_VERSION, __version__
from ninjemys.errors import MasterError, NinjemysError
from ninjemys.master.core import DEFAULT_PORT, Master
from ninjemys.net.addresses import advertised_host, split_uri
from ninjemys.roshome import log_directory
from ninjemys.tools.cli import entry, error

log = logging.getLogger("ninjemys.roscore")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="roscore", description="Start the ROS master, parameter server and rosout."
    )
    p.add_argument(
        "-p", "--port", type=int, help="master port (default: the port of ROS_MASTER_URI, else 11311)"
    )
    p.add_argument("-v", action="store_true", dest="verbose", help="verbose printing")
    p.add_argument(
        "-w", "--numworkers", type=int, help="accepted for compatibility (notifications are async)"
    )
    p.add_argument("-t", "--timeout", type=float, help="accepted for compatibility")
    p.add_argument("--master-logger-level", default="info", help="level of the master's log file")
    return p


def _port(requested: int | None) -> int:
    if requested is not None:
        if not 0 < requested < 65536:
            raise NinjemysError(f"-p {requested}: not a TCP port")
        return requested
    env_uri = os.environ.get("ROS_MASTER_URI", "").strip()
    if env_uri:
        try:
            return split_uri(env_uri)[1]
        except ValueError:
            raise NinjemysError(f"ROS_MASTER_URI={env_uri!r} is not an http://host:port/ URI") from None
    return DEFAULT_PORT


def _make_run_dir(run_id: str) -> Path | None:
    """Create <log root>/<run_id> and point <log root>/latest at it; None if the disk says no."""
    root = log_directory()
    run_dir = root / run_id
    try:
        run_dir.mkdir(parents=True, exist_ok=True)
        latest = root / "latest"
        tmp = root / f".latest.{os.getpid()}"
        tmp.unlink(missing_ok=True)
        tmp.symlink_to(run_dir)
        tmp.replace(latest)
    except OSError as exc:
        print(f"WARNING: cannot write logs under {root}: {exc}", file=sys.stderr)
        return None
    return run_dir


def _another_master(port: int) -> bool:
    from ninjemys.master.client import MasterClient

    try:
        MasterClient(f"http://127.0.0.1:{port}/", "/roscore", timeout=2.0).get_pid()
    except MasterError:
        return False
    return True


class _Rosout:
    """Starts rosout on a helper thread and stops it within a deadline."""

    def __init__(self, master_uri: str, run_dir: Path | None, announce: Callable[[], None]) -> None:
        self.node: Any = None  # a ninjemys.tools.rosout.Rosout once started (imported lazily)
        self._stop = threading.Event()
        self._thread = threading.Thread(
            target=self._run, args=(master_uri, run_dir, announce), name="rosout", daemon=True
        )
        self._thread.start()

    def _run(self, master_uri: str, run_dir: Path | None, announce: Callable[[], None]) -> None:
        try:
            from ninjemys.tools.rosout import Rosout

            node = Rosout(master_uri, run_dir)
        except Exception as exc:
            print(f"WARNING: rosout could not start: {exc}", file=sys.stderr, flush=True)
            return
        self.node = node
        if self._stop.is_set():
            node.stop()
            return
        announce()

    def stop(self, timeout: float) -> None:
        self._stop.set()
        node = self.node
        if node is not None:
            stopper = threading.Thread(target=node.stop, daemon=True)
            stopper.start()
            stopper.join(timeout)


async def _serve(master: Master, run_id: str, run_dir: Path | None) -> int:
    try:
        uri = await master.start()
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE:
            port = master.server.port
            if await asyncio.to_thread(_another_master, port):
                error(
                    "roscore cannot run as another roscore/master is already running "
                    f"on port {port}. Kill it first, or pick another port with -p."
                )
            else:
                error(f"port {port} is already in use by another program; pick another with -p")
            return 1
        error(f"cannot start the master: {exc}")
        return 1
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, master.stop, f"signal {sig.name}")
    master.set_param("/run_id", run_id)
    pid = os.getpid()
    out = sys.stdout
    out.write(
        f"auto-starting new master\nprocess[master]: started with pid [{pid}]\nROS_MASTER_URI={uri}\n\n"
        f"setting /run_id to {run_id}\n"
    )
    out.flush()

    def announce() -> None:
        loop.call_soon_threadsafe(_announce_rosout, pid)

    rosout = _Rosout(uri, run_dir, announce)
    await master.serve_until_stopped()
    if master.reason.startswith("external shutdown"):
        print(f"shutdown request: {master.reason}")
    print("[rosout-1] killing on exit\n[master] killing on exit")
    rosout.stop(0.8)
    print(
        "shutting down processing monitor...\n... shutting down processing monitor complete\ndone", flush=True
    )
    return 0


def _announce_rosout(pid: int) -> None:
    sys.stdout.write(f"process[rosout-1]: started with pid [{pid}]\nstarted core service [/rosout]\n")
    sys.stdout.flush()


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    port = _port(args.port)
    host = advertised_host()
    run_id = str(uuid.uuid1())
    run_dir = _make_run_dir(run_id)
    level = getattr(logging, str(args.master_logger_level).upper(), logging.INFO)
    master_log = logging.getLogger("ninjemys.master")
    master_log.setLevel(level)
    master_log.propagate = False
    if run_dir is not None:
        log_path = run_dir / f"roscore-{socket.gethostname()}-{os.getpid()}.log"
        handler = logging.FileHandler(log_path, encoding="utf-8", delay=True)
        handler.setFormatter(logging.Formatter("[%(name)s][%(levelname)s] %(asctime)s: %(message)s"))
        for name in ("ninjemys.master", "ninjemys.roscore", "ninjemys.net", "ninjemys.node"):
            logging.getLogger(name).addHandler(handler)
        print(f"... logging to {log_path}")
    distro = os.environ.get("ROS_DISTRO", ROS_DISTRO)
    print(
        "Press Ctrl-C to interrupt\n\n"
        f"started roscore (ninjemys {__version__})\nros_comm version {ROS_VERSION}\n\n\n"
        f"SUMMARY\n========\n\nPARAMETERS\n * /rosdistro: {distro}\n * /rosversion: {ROS_VERSION}\n\nNODES\n",
        flush=True,
    )
    master = Master("0.0.0.0", port, advertise=host)
    master.set_param("/rosdistro", distro)
    master.set_param("/rosversion", ROS_VERSION)
    return asyncio.run(_serve(master, run_id, run_dir))


console_main = entry(main)
