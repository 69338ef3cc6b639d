"""``make demo`` / ``python -m ninjemys.demo``: the seeds' first hour in one command.

It starts our roscore, the seeds' talker and listener, turtlesim (with its browser view) and a node
driving turtle1 around the third seed's 1 m square, prefixes every output line with the process name,
prints the URLs of the turtlesim view and the node graph, and on Ctrl-C (or after ``--duration``
seconds) stops them all, nodes first, and waits for every child to exit.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import IO

from ninjemys.launch.runner import DEATH_WRAPPER

_COLORS = {
    "roscore": "\033[36m",
    "talker": "\033[35m",
    "listener": "\033[32m",
    "turtlesim": "\033[33m",
    "square": "\033[34m",
}
_RESET = "\033[0m"


def _port_free(port: int) -> bool:
    import socket

    with socket.socket() as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def _pick_port(requested: int | None) -> int:
    from ninjemys.testing import free_port

    if requested:
        return requested
    return 11311 if _port_free(11311) else free_port()


def _pump(
    name: str,
    stream: IO[bytes],
    out: IO[str],
    lock: threading.Lock,
    color: bool,
    watch: Callable[[str], None] | None = None,
) -> None:
    """Copy a child's output line by line, each prefixed with the child's name."""
    prefix = f"{_COLORS[name]}[{name}]{_RESET} " if color else f"[{name}] "
    for raw in iter(stream.readline, b""):
        line = raw.decode("utf-8", "replace").rstrip("\n")
        if watch is not None:
            watch(line)
        with lock:
            out.write(prefix + line + "\n")
            out.flush()
    stream.close()


def _wait_for_master(uri: str, proc: subprocess.Popen[bytes], timeout: float) -> None:
    from ninjemys.errors import MasterError
    from ninjemys.master.client import MasterClient

    client = MasterClient(uri, "/demo", timeout=1.0)
    deadline = time.monotonic() + timeout
    try:
        while True:
            try:
                client.get_pid()
                return
            except MasterError:
                if proc.poll() is not None:
                    raise RuntimeError(f"roscore exited with code {proc.returncode}") from None
                if time.monotonic() > deadline:
                    raise RuntimeError(f"roscore did not answer at {uri} within {timeout:.0f} s") from None
                time.sleep(0.05)
    finally:
        client.close()


def _stop(procs: list[tuple[str, subprocess.Popen[bytes]]], grace: float = 5.0) -> None:
    """SIGINT every child (nodes before the master, as roslaunch does), then kill stragglers."""
    for _name, proc in reversed(procs):
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(grace)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def run(
    port: int | None = None,
    duration: float | None = None,
    color: bool | None = None,
    web_port: int = 0,
    turtlesim: bool = True,
) -> int:
    """Run the demo; returns when interrupted or after ``duration`` seconds."""
    port = _pick_port(port)
    uri = f"http://localhost:{port}/"
    env = dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1")
    env.setdefault("ROS_HOSTNAME", "localhost")
    color = sys.stdout.isatty() if color is None else color
    lock = threading.Lock()
    procs: list[tuple[str, subprocess.Popen[bytes]]] = []
    pumps: list[threading.Thread] = []

    def start(
        name: str, cmd: list[str], watch: Callable[[str], None] | None = None
    ) -> subprocess.Popen[bytes]:
        # children get SIGTERM if the demo itself dies (even by SIGKILL): nothing is left running
        proc = subprocess.Popen(
            [*DEATH_WRAPPER, *cmd],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
        )
        procs.append((name, proc))
        pump = threading.Thread(
            target=_pump, args=(name, proc.stdout, sys.stdout, lock, color, watch), daemon=True
        )
        pump.start()
        pumps.append(pump)
        return proc

    what = "roscore + talker + listener" + (" + turtlesim + square driver" if turtlesim else "")
    print(f"ninjemys demo: {what}, ROS_MASTER_URI={uri} (Ctrl-C to stop)", flush=True)
    interrupted = False
    try:
        core = start(
            "roscore",
            [
                sys.executable,
                "-c",
                "from ninjemys.tools.roscore import main; import sys; sys.exit(main(sys.argv[1:]))",
                "-p",
                str(port),
            ],
        )
        _wait_for_master(uri, core, timeout=20.0)
        start("talker", [sys.executable, "-m", "ninjemys.tutorials.talker"])
        start("listener", [sys.executable, "-m", "ninjemys.tutorials.listener"])
        if turtlesim:
            view_line: list[str] = []
            served = threading.Event()

            def watch(line: str) -> None:
                if line.startswith("turtlesim view:") and not served.is_set():
                    view_line.append(line)
                    served.set()

            start(
                "turtlesim",
                [
                    sys.executable,
                    "-m",
                    "ninjemys.sim.turtlesim_node",
                    "--port",
                    str(web_port),
                    "--no-browser",
                ],
                watch,
            )
            start("square", [sys.executable, "-m", "ninjemys.sim.square_driver"])
            if not served.wait(30.0):
                raise RuntimeError("turtlesim did not serve its view within 30 s")
            view, _, graph = view_line[0].partition("node graph:")
            with lock:
                print(
                    f"ninjemys demo: {view.strip()}  |  node graph: {graph.strip()}  |  Ctrl-C stops the demo.",
                    flush=True,
                )
        deadline = None if duration is None else time.monotonic() + duration
        while deadline is None or time.monotonic() < deadline:
            dead = [(n, p) for n, p in procs if p.poll() is not None]
            if dead:
                name, proc = dead[0]
                print(f"ninjemys demo: {name} exited with code {proc.returncode}; stopping", file=sys.stderr)
                return 1
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                procs[0][1].wait(min(1.0, remaining) if remaining is not None else 1.0)
            except subprocess.TimeoutExpired:
                pass
    except KeyboardInterrupt:
        interrupted = True
    except RuntimeError as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    finally:
        with _ignore_sigint():
            _stop(procs)
            for pump in pumps:
                pump.join(2.0)
    if interrupted:
        print("ninjemys demo: stopped", flush=True)
    return 0


class _ignore_sigint:  # noqa: N801 - used as a context manager
    """Let a second Ctrl-C not interrupt the cleanup of the children."""

    def __enter__(self) -> None:
        self._previous = signal.signal(signal.SIGINT, signal.SIG_IGN)

    def __exit__(self, *exc: object) -> None:
        signal.signal(signal.SIGINT, self._previous)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ninjemys.demo", description=__doc__.splitlines()[0])
    parser.add_argument(
        "-p", "--port", type=int, default=None, help="master port (default 11311, else a free one)"
    )
    parser.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    parser.add_argument("--no-color", action="store_true", help="plain output")
    parser.add_argument("--web-port", type=int, default=0, help="turtlesim view / graph port (default: any)")
    parser.add_argument("--no-turtlesim", action="store_true", help="only roscore, talker and listener")
    ns = parser.parse_args(argv)
    return run(
        ns.port,
        ns.duration,
        color=False if ns.no_color else None,
        web_port=ns.web_port,
        turtlesim=not ns.no_turtlesim,
    )


if __name__ == "__main__":
    sys.exit(main())
