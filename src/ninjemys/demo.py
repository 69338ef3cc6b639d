"""``make demo`` / ``python -m ninjemys.demo``: the seeds' robot navigating, in one command.

By default: our roscore, the PuzzleBot in the ``office`` world with navigation
(``roslaunch puzzlebot_navigation navigation.launch world:=office``: simulator, map_server, amcl,
move_base, safety monitor) and ``rviz`` showing the map, scan, particles, plan and camera. Click
"2D Nav Goal" in rviz and the robot drives there. ``--chatter`` is the seeds' first hour instead: the
talker and listener, turtlesim (with its browser view) and a node driving turtle1 around the third
seed's 1 m square.

Every output line is prefixed with the process name; the URLs are printed; on Ctrl-C (or after
``--duration`` seconds) everything stops, nodes first, and every child is waited for.
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
    "navigation": "\033[33m",
    "rviz": "\033[35m",
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
    from ninjemys.net.addresses import free_port

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


def _set_robot_description(uri: str) -> None:
    """``/robot_description`` from the PuzzleBot's URDF, as a launch file's ``<param textfile=...>`` does."""
    from ninjemys.master.client import MasterClient
    from ninjemys.packages.discovery import PackageIndex

    urdf = PackageIndex.from_environment().find("puzzlebot_sim").path / "robots" / "puzzlebot.urdf"
    client = MasterClient(uri, "/demo", timeout=5.0)
    try:
        client.set_param("/robot_description", urdf.read_text())
    finally:
        client.close()


def run(
    port: int | None = None,
    duration: float | None = None,
    color: bool | None = None,
    web_port: int = 0,
    turtlesim: bool = True,
    chatter: bool = False,
    world: str = "office",
    rate: float = 1.0,
    open_browser: bool = True,
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

    def served(prefix: str) -> tuple[Callable[[str], None], threading.Event, list[str]]:
        """A watcher for the first output line starting with ``prefix`` (a page's URL)."""
        seen: list[str] = []
        event = threading.Event()

        def watch(line: str) -> None:
            if line.startswith(prefix) and not event.is_set():
                seen.append(line)
                event.set()

        return watch, event, seen

    if chatter:
        what = "roscore + talker + listener" + (" + turtlesim + square driver" if turtlesim else "")
    else:
        what = f"roscore + PuzzleBot in the '{world}' world with navigation + rviz"
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
        if chatter:
            start("talker", [sys.executable, "-m", "ninjemys.tutorials.talker"])
            start("listener", [sys.executable, "-m", "ninjemys.tutorials.listener"])
        if chatter and turtlesim:
            watch, event, seen = served("turtlesim view:")
            start(
                "turtlesim",
                [
                    sys.executable,
                    "-m",
                    "ninjemys.web.turtlesim_view",
                    "--port",
                    str(web_port),
                    "--no-browser",
                ],
                watch,
            )
            start("square", [sys.executable, "-m", "ninjemys.sim.square_driver"])
            if not event.wait(30.0):
                raise RuntimeError("turtlesim did not serve its view within 30 s")
            view, _, graph = seen[0].partition("node graph:")
            with lock:
                print(
                    f"ninjemys demo: {view.strip()}  |  node graph: {graph.strip()}  |  Ctrl-C stops the demo.",
                    flush=True,
                )
        if not chatter:
            _set_robot_description(uri)
            _navigation(start, served, lock, world, rate, web_port, open_browser)
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


def _navigation(
    start: Callable[..., subprocess.Popen[bytes]],
    served: Callable[[str], tuple[Callable[[str], None], threading.Event, list[str]]],
    lock: threading.Lock,
    world: str,
    rate: float,
    web_port: int,
    open_browser: bool,
) -> None:
    """The PuzzleBot navigation stack and rviz; prints both pages' URLs."""
    from ninjemys.packages.discovery import PackageIndex
    from ninjemys.packages.shipped import shipped_executable

    sim_watch, sim_event, sim_seen = served("puzzlebot_sim view:")
    start(
        "navigation",
        [
            sys.executable,
            "-c",
            "from ninjemys.tools.roslaunch import console_main; console_main()",
            "puzzlebot_navigation",
            "navigation.launch",
            f"world:={world}",
            f"rate:={rate}",
        ],
        sim_watch,
    )
    config = PackageIndex.from_environment().find("puzzlebot_navigation").path / "rviz" / "navigation.rviz"
    rviz_watch, rviz_event, rviz_seen = served("rviz: http")
    rviz_args = ["-d", str(config), "--port", str(web_port)]
    if not open_browser:
        rviz_args.append("--no-browser")
    rviz = shipped_executable("rviz", "rviz")
    assert rviz is not None  # shipped with ninjemys (packages/shipped.py)
    start("rviz", rviz.command(rviz_args), rviz_watch)
    if not rviz_event.wait(60.0):
        raise RuntimeError("rviz did not serve its page within 60 s")
    if not sim_event.wait(60.0):
        raise RuntimeError("the simulator did not serve its view within 60 s")
    rviz_url = rviz_seen[0].split("rviz: ", 1)[1].strip()
    sim_url = sim_seen[0].split("puzzlebot_sim view:", 1)[1].split()[0]
    with lock:
        print(
            f"ninjemys demo: rviz: {rviz_url}  |  simulator: {sim_url}  |  "
            "click '2D Nav Goal', then a point of the map (drag for the heading)  |  Ctrl-C stops the demo.",
            flush=True,
        )


class _ignore_sigint:  # noqa: N801 - used as a context manager
    """Let a second Ctrl-C not interrupt the cleanup of the children."""

    def __enter__(self) -> None:
        self._previous = signal.signal(signal.SIGINT, signal.SIG_IGN)

    def __exit__(self, *exc: object) -> None:
        signal.signal(signal.SIGINT, self._previous)


def main(argv: list[str] | None = None) -> int:
    from ninjemys.commands import answer_sigint

    answer_sigint()  # Ctrl-C stops the demo even when it was started with SIGINT ignored
    parser = argparse.ArgumentParser(prog="python -m ninjemys.demo", description=__doc__.splitlines()[0])
    parser.add_argument(
        "-p", "--port", type=int, default=None, help="master port (default 11311, else a free one)"
    )
    parser.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    parser.add_argument("--no-color", action="store_true", help="plain output")
    parser.add_argument("--web-port", type=int, default=0, help="rviz / turtlesim view port (default: any)")
    parser.add_argument(
        "--chatter", action="store_true", help="the seeds' first hour: talker, listener, turtlesim"
    )
    parser.add_argument(
        "--no-turtlesim", action="store_true", help="with --chatter: only roscore, talker and listener"
    )
    parser.add_argument("--world", default="office", help="navigation world (empty, square, maze, office)")
    parser.add_argument("--rate", type=float, default=1.0, help="the simulator's real-time factor")
    parser.add_argument("--no-browser", action="store_true", help="only print the URLs (no rviz tab)")
    ns = parser.parse_args(argv)
    return run(
        ns.port,
        ns.duration,
        color=False if ns.no_color else None,
        web_port=ns.web_port,
        turtlesim=not ns.no_turtlesim,
        chatter=ns.chatter,
        world=ns.world,
        rate=ns.rate,
        open_browser=not ns.no_browser,
    )


if __name__ == "__main__":
    sys.exit(main())
