"""The rqt family as pages of the web tools: ``rqt``, ``rqt_plot``, ``rqt_console``, ``rqt_bag`` ...

Every command starts what its page needs in-process: a node on the ROS graph (anonymous, as rqt's),
the gateway on it (the page's one data path: raw ROS 1 bytes over the Foxglove subprotocol, decoded
in the browser) and the web app serving ``/rqt``. The page holds every plugin as a tab; a command
opens it on its own tab with its arguments in the URL (``/rqt?tool=plot&topic=/odom/pose/pose/position/x``).

Only rqt_bag has server-side state: the bag is read here with :class:`ninjemys.bag.reader.BagReader`
(the timeline comes from the bag's index, messages are fetched one at a time for the page to decode)
and played from here, published raw by this node like ``rosbag play``.
"""

from __future__ import annotations

import argparse
import base64
import bisect
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import Any
from urllib.parse import urlencode

from ninjemys.bag.play import stand_in_class
from ninjemys.bag.reader import BagReader
from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.errors import MasterError, NinjemysError
from ninjemys.node import Node
from ninjemys.serve.http import HttpError, Request, Response
from ninjemys.web.app import STATIC_DIR, WebApp
from ninjemys.web.browser import serve_until_stopped, stop_signals
from ninjemys.web.launched_name import LaunchedName, launched_name

DEFAULT_MASTER = "http://localhost:11311"
NSEC = 1_000_000_000
#: the tabs of the rqt page, in order: (tool id, title)
TOOLS = (
    ("graph", "Node Graph"),
    ("plot", "Plot"),
    ("console", "Console"),
    ("logger_level", "Logger Level"),
    ("bag", "Bag"),
    ("image_view", "Image View"),
    ("tf_tree", "TF Tree"),
    ("reconfigure", "Reconfigure"),
    ("topic", "Topic Monitor"),
    ("publisher", "Message Publisher"),
    ("service_caller", "Service Caller"),
    ("axclient", "Action Client"),
)


class BagSession:
    """The bags rqt_bag shows: their index as a timeline, single messages, and playback.

    Playback publishes the bag's bytes as recorded, each topic with the type, md5sum and definition
    of its connection (no deserialization), paced by the bag's stamps divided by ``speed``.
    """

    #: seconds playback waits for the subscribers of newly advertised topics to connect
    CONNECT_WAIT = 3.0

    def __init__(self, node: Node, paths: list[str]) -> None:
        self.node = node
        self.readers: list[BagReader] = []
        self.errors: list[str] = []
        for path in paths:
            try:
                self.readers.append(BagReader(path))
            except (NinjemysError, OSError) as exc:
                self.errors.append(str(exc))
        self._lock = threading.Lock()
        self._publishers: dict[str, Any] = {}
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.position: int | None = self.start
        self.speed = 1.0
        self.publish = True

    @property
    def start(self) -> int | None:
        starts = [r.start_time for r in self.readers if r.start_time is not None]
        return min(starts) if starts else None

    @property
    def end(self) -> int | None:
        ends = [r.end_time for r in self.readers if r.end_time is not None]
        return max(ends) if ends else None

    def info(self) -> dict[str, Any]:
        topics: dict[str, dict[str, Any]] = {}
        for reader in self.readers:
            by_topic: dict[str, set[int]] = {}
            for conn in reader.connections.values():
                by_topic.setdefault(conn.topic, set()).add(conn.id)
                topics.setdefault(conn.topic, {"name": conn.topic, "type": conn.datatype, "times": []})
            for topic, ids in by_topic.items():
                topics[topic]["times"].extend(reader.index_times(ids))
        for t in topics.values():
            t["times"].sort()
            t["count"] = len(t["times"])
        return {
            "paths": [str(r.path) for r in self.readers],
            "errors": self.errors,
            "warnings": [w for r in self.readers for w in r.warnings],
            "start": self.start,
            "end": self.end,
            "topics": sorted(topics.values(), key=lambda t: t["name"]),
        }

    def message(self, topic: str, at: int) -> dict[str, Any]:
        """The last message of ``topic`` at or before ``at`` (ns), or the first one after it."""
        best: tuple[int, Any] | None = None
        for reader in self.readers:
            conns = reader.topic_connections(topic)
            if not conns:
                continue
            times = reader.index_times({c.id for c in conns})
            i = bisect.bisect_right(times, at)
            when = times[i - 1] if i else (times[0] if times else None)
            if when is None:
                continue
            for raw in reader.read(topic, when, when):
                best = (raw.time, raw)
                break
        if best is None:
            raise HttpError(404, f"topic {topic} has no messages in the bag")
        return _encode_raw(best[1])

    def messages(self, topic: str, start: int | None, end: int | None, limit: int) -> list[dict[str, Any]]:
        out: list[dict[str, Any]] = []
        for reader in self.readers:
            for raw in reader.read(topic, start, end):
                out.append(_encode_raw(raw))
                if len(out) >= limit:
                    return out
        out.sort(key=lambda m: m["time"])
        return out

    # -- playback ---------------------------------------------------------------------------------
    def state(self) -> dict[str, Any]:
        return {
            "playing": self._thread is not None and self._thread.is_alive(),
            "position": self.position,
            "speed": self.speed,
            "publish": self.publish,
        }

    def play(self, start: int | None, speed: float, publish: bool) -> None:
        if speed <= 0:
            raise HttpError(400, f"speed must be positive, got {speed}")
        self.pause()
        self.speed = speed
        self.publish = publish
        if start is not None:
            self.position = start
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="rqt_bag-play", daemon=True)
        self._thread.start()

    def pause(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
        self._thread = None

    def _publisher(self, raw: Any) -> Any:
        conn = raw.connection
        pub = self._publishers.get(conn.topic)
        if pub is None:
            cls = stand_in_class(conn.datatype, conn.md5sum, conn.msg_def)
            pub = self.node.publisher(conn.topic, cls, queue_size=100, latch=conn.latching)
            self._publishers[conn.topic] = pub
        return pub

    def _advertise(self, streams: list[Any]) -> None:
        """Advertise every topic about to play, then wait (``CONNECT_WAIT`` at most) until each new
        publisher is connected to every subscriber the master lists for its topic. A message sent
        before a subscriber has connected is lost to it, and at 20x a short bag was over before a
        subscriber on a loaded machine had connected (rosbag play waits a fixed ``--delay`` after
        advertising for the same reason; here the wait ends as soon as everyone is there)."""
        new = []
        for raw in streams:
            if raw.connection.topic not in self._publishers:
                new.append(self._publisher(raw))
        if not new:
            return
        deadline = time.monotonic() + self.CONNECT_WAIT
        while not self._stop.is_set() and time.monotonic() < deadline:
            try:
                _, subscribed, _ = self.node.master.get_system_state()
            except MasterError:
                return  # no master: nobody to wait for
            wanted = {topic: set(nodes) - {self.node.name} for topic, nodes in subscribed}
            if all(wanted.get(p.resolved_name, set()) <= p.subscriber_ids() for p in new):
                return
            self._stop.wait(0.05)

    def _run(self) -> None:
        begin = self.position if self.position is not None else self.start
        if begin is None:
            return
        streams = [m for r in self.readers for m in r.read(None, begin, None)]
        streams.sort(key=lambda m: m.time)
        self._advertise(streams)
        wall0 = time.monotonic()
        for raw in streams:
            due = wall0 + (raw.time - begin) / NSEC / self.speed
            while not self._stop.is_set():
                left = due - time.monotonic()
                if left <= 0:
                    break
                self.position = begin + int((time.monotonic() - wall0) * self.speed * NSEC)
                self._stop.wait(min(left, 0.05))
            if self._stop.is_set():
                return
            self.position = raw.time
            if self.publish:
                self._publisher(raw).publish_raw(bytes(raw.data))
        self.position = self.end

    def close(self) -> None:
        self.pause()
        for reader in self.readers:
            reader.close()


def _encode_raw(raw: Any) -> dict[str, Any]:
    conn = raw.connection
    return {
        "topic": conn.topic,
        "type": conn.datatype,
        "definition": conn.msg_def,
        "time": raw.time,
        "data": base64.b64encode(bytes(raw.data)).decode("ascii"),
    }


def _int_arg(request: Request, name: str) -> int | None:
    value = request.arg(name)
    if value is None or value == "":
        return None
    try:
        return int(value)
    except ValueError:
        raise HttpError(400, f"?{name}= must be an integer (ns), got {value!r}") from None


class RqtPage:
    """The ``/rqt`` page (every plugin as a tab) and rqt_bag's API on a :class:`WebApp`."""

    def __init__(self, app: WebApp, node: Node, bags: list[str] | None = None) -> None:
        self.bag = BagSession(node, bags or [])
        app.add_page("rqt", "/rqt")
        s = app.server
        s.route(
            "GET",
            "/rqt",
            lambda _r: Response((STATIC_DIR / "rqt.html").read_bytes(), 200, "text/html; charset=utf-8"),
        )
        s.route("GET", "/api/rqt/bag", lambda _r: Response(self.bag.info()))
        s.route("GET", "/api/rqt/bag/message", self._message)
        s.route("GET", "/api/rqt/bag/messages", self._messages)
        s.route("GET", "/api/rqt/bag/state", lambda _r: Response(self.bag.state()))
        s.route("POST", "/api/rqt/bag/play", self._play)
        s.route("POST", "/api/rqt/bag/pause", self._pause)

    def _message(self, request: Request) -> Response:
        topic = request.arg("topic")
        at = _int_arg(request, "time")
        if not topic or at is None:
            raise HttpError(400, "expected ?topic=<name>&time=<ns>")
        return Response(self.bag.message(topic, at))

    def _messages(self, request: Request) -> Response:
        topic = request.arg("topic")
        if not topic:
            raise HttpError(400, "expected ?topic=<name>")
        limit = _int_arg(request, "limit") or 5000
        return Response(self.bag.messages(topic, _int_arg(request, "start"), _int_arg(request, "end"), limit))

    def _play(self, request: Request) -> Response:
        body = request.json() or {}
        if not isinstance(body, dict):
            raise HttpError(400, "expected {start, speed, publish}")
        try:
            speed = float(body.get("speed", 1.0))
        except (TypeError, ValueError):
            raise HttpError(400, f"speed must be a number, got {body.get('speed')!r}") from None
        start = body.get("start")
        self.bag.play(int(start) if start is not None else None, speed, bool(body.get("publish", True)))
        return Response(self.bag.state())

    def _pause(self, _request: Request) -> Response:
        self.bag.pause()
        return Response(self.bag.state())


class Rqt:
    """rqt in-process: node + gateway + web app; ``start()`` returns the app's base URL."""

    def __init__(
        self,
        master_uri: str,
        name: str = "rqt_gui_py_node",
        bags: list[str] | None = None,
        host: str = "127.0.0.1",
        port: int = 0,
        update_period: float = 1.0,
        launched: LaunchedName | None = None,
    ) -> None:
        self.node = (launched or LaunchedName.anonymous_default(name)).node(master_uri)
        try:
            options = GatewayOptions(node_name=self.node.name, update_period=update_period)
            self.gateway = Gateway(options, node=self.node)
            self.gateway.start()
            self.app = WebApp(master_uri, caller_id=self.node.name, host=host, port=port)
            self.app.add_gateway(self.gateway, "/ws")
            self.page = RqtPage(self.app, self.node, bags)
        except BaseException:
            self.node.shutdown("rqt failed to start")
            raise

    def start(self) -> str:
        return self.app.start()

    def stop(self) -> None:
        self.page.bag.close()
        self.gateway.shutdown()
        self.app.stop()
        self.node.shutdown("rqt closed")


def tool_url(base: str, tool: str | None, query: list[tuple[str, str]] | None = None) -> str:
    """The page URL that opens ``tool``'s tab with its arguments (``base`` ends with '/')."""
    params = ([("tool", tool)] if tool else []) + list(query or [])
    return base + "rqt" + ("?" + urlencode(params) if params else "")


# -- commands -------------------------------------------------------------------------------------


def _common(p: argparse.ArgumentParser) -> argparse.ArgumentParser:
    p.add_argument(
        "--port", type=int, default=int(os.environ.get("NINJEMYS_WEB_PORT", "0")), help="HTTP port"
    )
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the URL")
    return p


def _serve(
    prog: str,
    tool: str | None,
    query: list[tuple[str, str]],
    args: argparse.Namespace,
    bags: list[str] | None = None,
    argv: list[str] | None = None,
) -> int:
    master_uri = os.environ.get("ROS_MASTER_URI", DEFAULT_MASTER)
    try:
        launched = launched_name(prog, argv if argv is not None else sys.argv[1:])
        rqt = Rqt(master_uri, prog, bags, args.host, args.port, launched=launched)
    except NinjemysError as exc:
        print(f"ERROR: {prog}: {exc}", file=sys.stderr)
        return 1
    stopped = stop_signals()
    try:
        base = rqt.start()
    except OSError as exc:
        rqt.stop()
        print(
            f"ERROR: cannot serve {prog} on {args.host}:{args.port}: {exc.strerror or exc}", file=sys.stderr
        )
        return 1
    for error in rqt.page.bag.errors:
        print(f"{prog}: {error}", file=sys.stderr)
    url = tool_url(base, tool, query)
    print(f"{prog}: {url}", flush=True)
    return serve_until_stopped(url, not args.no_browser, rqt.stop, stopped)


def _ros_args(argv: list[str] | None) -> list[str]:
    # ROS passes remappings (name:=value) and __name/__ns/__log args: the node takes them
    # (launched_name), the page's own options do not
    return [a for a in (argv if argv is not None else sys.argv[1:]) if ":=" not in a]


def _simple(prog: str, tool: str | None, description: str) -> Callable[[list[str] | None], int]:
    def main(argv: list[str] | None = None) -> int:
        args = _common(argparse.ArgumentParser(prog=prog, description=description)).parse_args(
            _ros_args(argv)
        )
        return _serve(prog, tool, [], args, argv=argv)

    return main


#: rqt's plugin names (``rqt -s rqt_plot``) -> the page's tabs
PLUGINS = {
    "rqt_graph": "graph",
    "rqt_plot": "plot",
    "rqt_console": "console",
    "rqt_logger_level": "logger_level",
    "rqt_bag": "bag",
    "rqt_image_view": "image_view",
    "rqt_tf_tree": "tf_tree",
    "rqt_reconfigure": "reconfigure",
    "rqt_topic": "topic",
    "rqt_publisher": "publisher",
    "rqt_service_caller": "service_caller",
}


def rqt_main(argv: list[str] | None = None) -> int:
    p = _common(argparse.ArgumentParser(prog="rqt", description="Every rqt plugin as a tab of one page."))
    p.add_argument(
        "-s", "--standalone", metavar="PLUGIN", choices=sorted(PLUGINS), help="open on this plugin's tab"
    )
    args = p.parse_args(_ros_args(argv))
    return _serve("rqt", PLUGINS[args.standalone] if args.standalone else None, [], args, argv=argv)


console_plugin_main = _simple("rqt_console", "console", "Messages of /rosout_agg, filtered, in a browser.")
logger_level_main = _simple("rqt_logger_level", "logger_level", "Set the logger levels of running nodes.")
tf_tree_main = _simple("rqt_tf_tree", "tf_tree", "The TF frame tree with rates and delays.")
topic_main = _simple("rqt_topic", "topic", "Monitor topics: rate, bandwidth and last value.")
publisher_main = _simple("rqt_publisher", "publisher", "Publish messages from a browser.")
service_caller_main = _simple("rqt_service_caller", "service_caller", "Call services from a browser.")


def plot_main(argv: list[str] | None = None) -> int:
    p = _common(argparse.ArgumentParser(prog="rqt_plot", description="Plot numeric fields of topics live."))
    p.add_argument("topics", nargs="*", help="fields to plot, e.g. /turtle1/pose/x (several: a,b or /t/x:y)")
    args = p.parse_args(_ros_args(argv))
    fields: list[str] = []
    for arg in args.topics:
        for item in arg.split(","):
            # rqt_plot's /topic/a:b form plots /topic/a and /topic/b
            head, _, rest = item.rpartition("/")
            parts = rest.split(":") if ":" in rest else [rest]
            fields.extend(f"{head}/{part}" for part in parts if part)
    return _serve("rqt_plot", "plot", [("topic", f) for f in fields], args, argv=argv)


def bag_main(argv: list[str] | None = None) -> int:
    p = _common(argparse.ArgumentParser(prog="rqt_bag", description="Browse, play and plot bag files."))
    p.add_argument("bagfiles", nargs="*", help="bag files to open")
    args = p.parse_args(_ros_args(argv))
    return _serve("rqt_bag", "bag", [], args, bags=args.bagfiles, argv=argv)


def image_view_main(argv: list[str] | None = None) -> int:
    p = _common(argparse.ArgumentParser(prog="rqt_image_view", description="Show an image topic."))
    p.add_argument("image", nargs="?", help="image topic to show first")
    args = p.parse_args(_ros_args(argv))
    return _serve(
        "rqt_image_view", "image_view", [("topic", args.image)] if args.image else [], args, argv=argv
    )


def reconfigure_main(argv: list[str] | None = None) -> int:
    p = _common(
        argparse.ArgumentParser(prog="rqt_reconfigure", description="Edit dynamic_reconfigure servers.")
    )
    p.add_argument("node", nargs="?", help="server to open first")
    args = p.parse_args(_ros_args(argv))
    return _serve(
        "rqt_reconfigure", "reconfigure", [("node", args.node)] if args.node else [], args, argv=argv
    )


def axclient_main(argv: list[str] | None = None) -> int:
    p = _common(argparse.ArgumentParser(prog="axclient.py", description="Send goals to an action server."))
    p.add_argument("action", help="action name, e.g. /fibonacci")
    p.add_argument("type", nargs="?", help="action type, e.g. actionlib_tutorials/FibonacciAction")
    args = p.parse_args(_ros_args(argv))
    query = [("action", args.action)] + ([("type", args.type)] if args.type else [])
    return _serve("axclient", "axclient", query, args, argv=argv)


rqt_console_main: Any = entry(rqt_main)
plot_console_main: Any = entry(plot_main)
console_console_main: Any = entry(console_plugin_main)
logger_level_console_main: Any = entry(logger_level_main)
bag_console_main: Any = entry(bag_main)
image_view_console_main: Any = entry(image_view_main)
tf_tree_console_main: Any = entry(tf_tree_main)
reconfigure_console_main: Any = entry(reconfigure_main)
topic_console_main: Any = entry(topic_main)
publisher_console_main: Any = entry(publisher_main)
service_caller_console_main: Any = entry(service_caller_main)
axclient_console_main: Any = entry(axclient_main)
