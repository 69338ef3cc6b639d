"""``gzserver``, ``gzclient`` and ``gazebo``: Gazebo's commands, played by the PuzzleBot simulator.

``gzserver [-u] [-e physics] [--verbose] [-s plugin ...] [world]`` runs the simulator as the node
``gazebo`` on a Gazebo world (``worlds/empty.world`` by default), with no robot until
``spawn_model`` brings one, physics paused with ``-u``; it serves the browser view (unless
``--headless``) and leaves its address in the parameter ``/gazebo/gui_url`` (an empty address when
headless). ``gzclient`` is not Gazebo's 3D client: it waits for that parameter and opens the
simulator's browser view (the world from above with the robots, their scans and camera images), as
Gazebo's client attaches to a running server; facing a headless server it says so and exits 1 (there
is nothing to attach to), and an address that does not answer (a server that has gone) is not
opened. ``gazebo`` is both in one process. Gazebo's options this simulator has no use for (``-r``, ``-s``, ``-g``,
``--seed`` ...) are accepted and named once.
"""

from __future__ import annotations

import argparse
import sys
import threading
import urllib.request
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ninjemys.commands import entry
from ninjemys.errors import NinjemysError
from ninjemys.node import Node
from ninjemys.node.run import run_node
from ninjemys.web.browser import open_if_display

if TYPE_CHECKING:
    from ninjemys.node.log import NodeLog
    from ninjemys.sim.puzzlebot_node import SimNode

GUI_URL_PARAM = "/gazebo/gui_url"


def _parser(prog: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description="Gazebo's server, played by the ninjemys simulator.")
    p.add_argument("world", nargs="?", default="worlds/empty.world", help="a .world file")
    p.add_argument("-u", "--pause", action="store_true", help="start the server in a paused state")
    p.add_argument("-e", "--physics", default="ode", help="physics engine (accepted; one engine here)")
    p.add_argument("--verbose", action="store_true", help="more output")
    p.add_argument("-r", "--record", action="store_true", help="(accepted, not recorded)")
    p.add_argument("-s", "--server-plugin", action="append", default=[], help="(accepted, ignored)")
    p.add_argument("-g", "--gui-plugin", action="append", default=[], help="(accepted, ignored)")
    p.add_argument("--seed", type=float, default=None, help="random seed of the sensor noise")
    p.add_argument("--headless", action="store_true", help="serve no browser view")
    p.add_argument("--port", type=int, default=0, help="browser view port (default: any free port)")
    p.add_argument("--host", default="127.0.0.1", help="browser view address (default: localhost only)")
    return p


def _view_with_url(sim_node: SimNode, options: argparse.Namespace, log: NodeLog) -> Callable[[], None] | None:
    """The simulator's browser view, its address left in /gazebo/gui_url for gzclient."""
    from ninjemys.web.puzzlebot_view import start_view

    stop = start_view(sim_node, options, log)
    url = getattr(sim_node.view, "url", None)
    if stop is not None and url:
        try:
            sim_node.node.set_param(GUI_URL_PARAM, url)
        except NinjemysError as exc:
            log.warn("could not set %s: %s", GUI_URL_PARAM, exc)
    return stop


def _headless_view(sim_node: SimNode, _options: argparse.Namespace, log: NodeLog) -> Callable[[], None]:
    """No view: an empty /gazebo/gui_url tells gzclient there is nothing to attach to."""
    try:
        sim_node.node.set_param(GUI_URL_PARAM, "")
    except NinjemysError as exc:
        log.warn("could not set %s: %s", GUI_URL_PARAM, exc)
    return lambda: None


def server_main(argv: list[str] | None, open_browser: bool, prog: str) -> int:
    """gzserver (``open_browser`` False) or gazebo (True): the simulator on a Gazebo world."""
    from ninjemys.sim import puzzlebot_node

    argv = sys.argv[1:] if argv is None else argv
    ros_args = [a for a in argv if ":=" in a]
    options, unknown = _parser(prog).parse_known_args([a for a in argv if ":=" not in a])
    ignored = list(unknown)
    if options.record:
        ignored.append("-r")
    ignored += [f"-s {p}" for p in options.server_plugin] + [f"-g {p}" for p in options.gui_plugin]
    ignored = [i for i in ignored if "libgazebo_ros_" not in i]  # what gazebo_ros' scripts add themselves
    if ignored:
        print(f"{prog}: ignoring options this simulator has no use for: {' '.join(ignored)}", file=sys.stderr)
    sim_args = list(ros_args)
    if not any(a.startswith("__name:=") for a in ros_args):
        sim_args.insert(0, "__name:=gazebo")
    sim_args += [f"_world:={options.world}", "_no_robot:=true"]
    if options.pause:
        sim_args.append("_paused:=true")
    if options.seed is not None:
        sim_args.append(f"_seed:={int(options.seed)}")
    sim_args += ["--port", str(options.port), "--host", options.host]
    if not open_browser:
        sim_args.append("--no-browser")
    return puzzlebot_node.main(sim_args, view=_headless_view if options.headless else _view_with_url)


def gzserver_main(argv: list[str] | None = None) -> int:
    return server_main(argv, False, "gzserver")


def gazebo_main(argv: list[str] | None = None) -> int:
    return server_main(argv, True, "gazebo")


def _answers(url: str) -> bool:
    """Whether the view at ``url`` is served (a parameter left by a server that has gone is not)."""
    try:
        with urllib.request.urlopen(url, timeout=2.0) as reply:
            return bool(200 <= reply.status < 400)
    except (OSError, ValueError):
        return False


def gzclient_main(argv: list[str] | None = None) -> int:
    """Wait for a server's view and open it (or print its address where there is no display); exit 1
    when the server is headless (there is no view to attach to)."""
    argv = sys.argv[1:] if argv is None else argv
    ros_args = [a for a in argv if ":=" in a]
    print(
        "gzclient: this is not Gazebo's 3D client: it opens the ninjemys simulator's browser view",
        flush=True,
    )
    code = [0]

    def build(node: Node) -> None:
        def attach() -> None:
            waited = 0.0
            stale = ""
            while not node.is_shutdown:
                try:
                    url: Any = node.get_param(GUI_URL_PARAM, None)
                except NinjemysError:
                    url = None
                if url == "":
                    print("gzclient: gzserver runs headless: there is no view to attach to", flush=True)
                    code[0] = 1
                    node.shutdown("gzserver is headless")
                    return
                if url and _answers(str(url)):
                    print(f"gzclient: simulator view {url}", flush=True)
                    open_if_display(str(url))
                    return
                if url and url != stale:
                    stale = str(url)
                    node.log.warn("the view at %s does not answer (a gzserver that has gone?): waiting", url)
                if waited == 5.0:
                    node.log.info("waiting for gzserver's view (%s)", GUI_URL_PARAM)
                waited += 0.25
                threading.Event().wait(0.25)

        threading.Thread(target=attach, name="gzclient-attach", daemon=True).start()

    status = run_node("gazebo_gui", ros_args, build)
    return code[0] or status


gzserver_console = entry(gzserver_main)
gzclient_console = entry(gzclient_main)
gazebo_console = entry(gazebo_main)
