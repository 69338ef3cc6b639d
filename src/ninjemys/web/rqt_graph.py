"""``rqt_graph``: start the web tools and show the node graph of the current ROS master.

Prints the URL (and opens a browser when there is a display), then serves until Ctrl-C. The page's
data comes through a gateway on the same server (its connection graph, and a subscription for the
topic whose details are open); the gateway's node counts as debug plumbing on the page.
"""

from __future__ import annotations

import argparse
import os
import sys

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.web.app import WebApp
from ninjemys.web.browser import serve_until_stopped, stop_signals
from ninjemys.web.launched_name import launched_name

DEFAULT_MASTER = "http://localhost:11311"


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rqt_graph", description="Show the ROS computation graph in a browser.")
    p.add_argument(
        "--port", type=int, default=int(os.environ.get("NINJEMYS_WEB_PORT", "0")), help="HTTP port"
    )
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the URL")
    return p


def main(argv: list[str] | None = None) -> int:
    # ROS passes remappings (name:=value) and __name/__ns/__log args: the node takes them
    # (launched_name), the page's own options do not
    argv = list(argv or [])
    args = _parser().parse_args([a for a in argv if ":=" not in a])
    master_uri = os.environ.get("ROS_MASTER_URI", DEFAULT_MASTER)
    app = WebApp(master_uri, caller_id="/rqt_graph", host=args.host, port=args.port)
    stopped = stop_signals()
    try:
        url = app.start()  # the port first: a busy one is a one-line error before any ROS traffic
    except OSError as exc:
        print(
            f"ERROR: cannot serve the web tools on {args.host}:{args.port}: {exc.strerror or exc}",
            file=sys.stderr,
        )
        return 1
    node = launched_name("rqt_graph", argv).node(master_uri)
    gateway = Gateway(GatewayOptions(node_name=node.name, hide_own_node=True, update_period=0.5), node=node)
    gateway.start()
    app.add_gateway(gateway)

    def stop() -> None:
        app.stop()
        gateway.shutdown()
        node.shutdown("rqt_graph closed")

    print(f"rqt_graph: node graph of {master_uri} at {url}", flush=True)
    return serve_until_stopped(url, not args.no_browser, stop, stopped)


console_main = entry(main)
