"""``rviz``: the 3D visualizer, as a page of the web tools (``rosrun rviz rviz``, ``rviz -d file.rviz``).

The command starts what the page needs in-process: a node on the ROS graph (``/rviz_<pid>_<ms>``,
anonymous as rviz's), the gateway on it (the page's one data path: raw ROS 1 bytes over the Foxglove
subprotocol, decoded in the browser) and the web app serving ``/rviz``. The page's display list comes
from the ``.rviz`` file (``GET /api/rviz/config``) and is saved back to it (``POST``), in rviz's layout.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from pathlib import Path
from typing import Any

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.errors import NinjemysError
from ninjemys.serve.http import HttpError, Request, Response
from ninjemys.web import rvizconfig
from ninjemys.web.app import STATIC_DIR, WebApp
from ninjemys.web.browser import serve_until_stopped, stop_signals
from ninjemys.web.launched_name import LaunchedName, launched_name

DEFAULT_MASTER = "http://localhost:11311"
#: where rviz saves when it was not started with -d
DEFAULT_FILE = Path("~/.rviz/default.rviz")


class RvizPage:
    """The ``/rviz`` page and its config API on a :class:`WebApp` (which must serve a gateway)."""

    def __init__(self, app: WebApp, config_path: str | None = None, fixed_frame: str | None = None) -> None:
        self.path = Path(config_path).expanduser() if config_path else DEFAULT_FILE.expanduser()
        self.error: str | None = None
        self._lock = threading.Lock()
        if config_path:
            try:
                self.config = rvizconfig.load(self.path)
            except rvizconfig.RvizConfigError as exc:
                # rviz falls back to its defaults; the page names the broken file
                self.error = str(exc)
                self.config = rvizconfig.default_config()
        elif self.path.is_file():
            try:
                self.config = rvizconfig.load(self.path)
            except rvizconfig.RvizConfigError as exc:
                self.error = str(exc)
                self.config = rvizconfig.default_config()
        else:
            self.config = rvizconfig.default_config()
        if fixed_frame:
            self.config.fixed_frame = fixed_frame
        app.add_page("RViz", "/rviz")
        s = app.server
        s.route(
            "GET",
            "/rviz",
            lambda _r: Response((STATIC_DIR / "rviz.html").read_bytes(), 200, "text/html; charset=utf-8"),
        )
        s.route("GET", "/api/rviz/config", self._get)
        s.route("POST", "/api/rviz/config", self._save)

    def _get(self, _request: Request) -> Response:
        with self._lock:
            body = self.config.to_page()
        body["path"] = str(self.path)
        body["error"] = self.error
        return Response(body)

    def _save(self, request: Request) -> Response:
        # JSON only: a cross-site form or text/plain POST cannot write the file (it needs a CORS
        # preflight, which this server does not grant); and only the file rviz was started with
        if not request.headers.get("content-type", "").startswith("application/json"):
            raise HttpError(415, "POST /api/rviz/config takes application/json")
        page = request.json()
        if not isinstance(page, dict) or not isinstance(page.get("displays"), list):
            raise HttpError(400, "expected {fixedFrame, displays: [...]}")
        target = self.path
        with self._lock:
            text = rvizconfig.dump(page, self.config)
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_text(text, encoding="utf-8")
            except OSError as exc:
                raise HttpError(500, f"cannot write {target}: {exc.strerror or exc}") from None
            self.config = rvizconfig.parse(text, str(target))
            self.path = target
            self.error = None
        return Response({"ok": True, "path": str(target)})


class Rviz:
    """rviz in-process: node + gateway + web app. ``start()`` returns the page's URL."""

    def __init__(
        self,
        master_uri: str,
        config_path: str | None = None,
        fixed_frame: str | None = None,
        host: str = "127.0.0.1",
        port: int = 0,
        update_period: float = 1.0,
        launched: LaunchedName | None = None,
    ) -> None:
        self.node = (launched or LaunchedName.anonymous_default("rviz")).node(master_uri)
        try:
            options = GatewayOptions(node_name=self.node.name, update_period=update_period)
            self.gateway = Gateway(options, node=self.node)
            self.gateway.start()
            self.app = WebApp(master_uri, caller_id=self.node.name, host=host, port=port)
            self.app.add_gateway(self.gateway, "/ws")
            self.page = RvizPage(self.app, config_path, fixed_frame)
        except BaseException:
            self.node.shutdown("rviz failed to start")
            raise

    def start(self) -> str:
        return self.app.start() + "rviz"

    def stop(self) -> None:
        self.gateway.shutdown()
        self.app.stop()
        self.node.shutdown("rviz closed")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rviz", description="3D visualization of the ROS graph, in a browser.")
    p.add_argument("-d", "--display-config", help="a .rviz file to load (and save to)")
    p.add_argument("-f", "--fixed-frame", help="the fixed frame (overrides the file's)")
    p.add_argument(
        "--port", type=int, default=int(os.environ.get("NINJEMYS_WEB_PORT", "0")), help="HTTP port"
    )
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the URL")
    return p


def _wait_for_master(uri: str) -> None:
    """Block until the master answers, saying so once (rviz waits for roscore rather than failing)."""
    from ninjemys.errors import MasterError
    from ninjemys.master.client import MasterClient

    client = MasterClient(uri, "/rviz", timeout=2.0)
    told = False
    try:
        while True:
            try:
                client.get_pid()
                return
            except MasterError:
                if not told:
                    print(
                        f"rviz: waiting for the master at {uri} (start roscore)", file=sys.stderr, flush=True
                    )
                    told = True
                time.sleep(0.5)
    finally:
        client.close()


def main(argv: list[str] | None = None) -> int:
    # ROS passes remappings (name:=value) and __name/__ns/__log args: the node takes them
    # (launched_name), the page's own options do not
    argv = argv if argv is not None else sys.argv[1:]
    args = _parser().parse_args([a for a in argv if ":=" not in a])
    master_uri = os.environ.get("ROS_MASTER_URI", DEFAULT_MASTER)
    _wait_for_master(master_uri)
    try:
        launched = launched_name("rviz", argv)
        rviz = Rviz(
            master_uri, args.display_config, args.fixed_frame, args.host, args.port, launched=launched
        )
    except NinjemysError as exc:
        print(f"ERROR: rviz: {exc}", file=sys.stderr)
        return 1
    stopped = stop_signals()
    try:
        url = rviz.start()
    except OSError as exc:
        rviz.stop()
        print(f"ERROR: cannot serve rviz on {args.host}:{args.port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    if rviz.page.error:
        print(f"rviz: {rviz.page.error} (opened with the default displays)", file=sys.stderr)
    print(f"rviz: {url}", flush=True)
    return serve_until_stopped(url, not args.no_browser, rviz.stop, stopped)


console_main: Any = entry(main)
