"""``smach_viewer``: the state machines of every smach introspection server, drawn live in a browser.

``rosrun smach_viewer smach_viewer.py`` (as in ROS 1) starts the web tools with a page that finds
every ``*/smach/container_structure`` and ``*/smach/container_status`` topic through the gateway,
draws each container (nested ones inside their parent), its states, transitions and outcomes, and
highlights the active states as status messages arrive. The page has no data path but the gateway.
"""

from __future__ import annotations

import argparse
import os
import sys

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.errors import NinjemysError
from ninjemys.node.run import start_node
from ninjemys.serve.http import Response
from ninjemys.web.app import STATIC_DIR, WebApp
from ninjemys.web.browser import serve_until_stopped, stop_signals

PAGE = "/smach_viewer"


class SmachViewer:
    """The viewer's node, gateway and web app; ``start()`` returns the page URL."""

    def __init__(self, node: object, host: str = "127.0.0.1", port: int = 0) -> None:
        self.node = node
        self.gateway = Gateway(GatewayOptions(node_name=node.name, update_period=0.5), node=node)  # type: ignore[attr-defined]
        self.gateway.start()
        self.app = WebApp(node.master_uri, caller_id=node.name, host=host, port=port)  # type: ignore[attr-defined]
        self.app.add_gateway(self.gateway, "/ws")
        self.app.add_page("SMACH viewer", PAGE)
        self.app.server.route(
            "GET",
            PAGE,
            lambda _r: Response(
                (STATIC_DIR / "smach_viewer.html").read_bytes(), 200, "text/html; charset=utf-8"
            ),
        )

    def start(self) -> str:
        return f"{self.app.start()}{PAGE.lstrip('/')}"

    def stop(self) -> None:
        self.gateway.shutdown()
        self.app.stop()
        self.node.shutdown("smach_viewer closed")  # type: ignore[attr-defined]


def main(argv: list[str] | None = None) -> int:
    """``rosrun smach_viewer smach_viewer.py [--port N] [--no-browser]`` (ROS remappings accepted)."""
    argv = sys.argv[1:] if argv is None else argv
    p = argparse.ArgumentParser(prog="smach_viewer.py", description=__doc__.splitlines()[0])
    p.add_argument(
        "--port", type=int, default=int(os.environ.get("NINJEMYS_WEB_PORT", "0")), help="HTTP port"
    )
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the URL")
    args, _unknown = p.parse_known_args([a for a in argv if ":=" not in a])
    try:
        node = start_node("smach_viewer", [a for a in argv if ":=" in a])
    except NinjemysError as exc:
        print(f"smach_viewer: {exc}", file=sys.stderr)
        return 1
    viewer = SmachViewer(node, args.host, args.port)
    stopped = stop_signals()
    try:
        url = viewer.start()
    except OSError as exc:
        viewer.stop()
        print(f"ERROR: cannot serve on {args.host}:{args.port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(f"smach_viewer: {url}", flush=True)
    return serve_until_stopped(url, not args.no_browser, viewer.stop, stopped)


console_main = entry(main)
