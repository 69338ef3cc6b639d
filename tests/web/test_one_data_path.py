"""One data path to the browser (docs/architecture.md): live ROS data reaches every page only through
the gateway's WebSocket (Foxglove channels, app channels, the connection graph). Checked on the
source: only the gateway client opens a WebSocket, no page uses Server-Sent Events, and the HTTP routes
of the web tools and the gateway are pages, schemas and files, each listed here with why it is not a
second data path. A new route fails this test until it is listed (or moved onto the gateway)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src" / "ninjemys"
STATIC = SRC / "web" / "static"

#: (method, path) -> why it is not live ROS data
ALLOWED_ROUTES = {
    ("GET", "/"): "a page",
    ("GET", "/graph"): "a page",
    ("GET", "/rqt"): "a page",
    ("GET", "/rviz"): "a page",
    ("GET", "/turtlesim"): "a page",
    ("GET", "/puzzlebot"): "a page",
    ("GET", "/api/pages"): "the index of pages for the navigation bar",
    ("GET", "/api/msgdef"): "a message definition by type name (a schema, as Foxglove advertises them)",
    ("GET", "/api/rviz/config"): "the .rviz file the page was opened with",
    ("POST", "/api/rviz/config"): "saving the .rviz file",
    ("GET", "/api/rqt/bag"): "rqt_bag reads a bag file on disk, not the live graph",
    ("GET", "/api/rqt/bag/message"): "rqt_bag: one message of the bag file",
    ("GET", "/api/rqt/bag/messages"): "rqt_bag: a topic's messages in the bag file",
    ("GET", "/api/rqt/bag/state"): "rqt_bag: the player's state",
    (
        "POST",
        "/api/rqt/bag/play",
    ): "rqt_bag: play the file (onto ROS topics, which the pages see via the gateway)",
    ("POST", "/api/rqt/bag/pause"): "rqt_bag: pause the player",
    ("GET", "/api/turtlesim/snapshot.png"): "a still image of the canvas (screenshots and tests)",
    ("GET", "/api/puzzlebot/floor.png"): "a picture on the simulated world's floor (a file's texture)",
    ("GET", "/api/bridge/status"): "the gateway's own status (clients, queues)",
}


def literal_routes() -> list[tuple[str, str, str]]:
    """(method, path, file:line) of every ``.route("METHOD", "/literal", ...)`` in the apps."""
    found = []
    for folder in ("web", "bridge", "serve", "sim", "nav"):
        for path in sorted((SRC / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if (
                    isinstance(node, ast.Call)
                    and isinstance(node.func, ast.Attribute)
                    and node.func.attr == "route"
                    and len(node.args) >= 2
                    and all(isinstance(a, ast.Constant) and isinstance(a.value, str) for a in node.args[:2])
                ):
                    method, route = node.args[0].value, node.args[1].value  # type: ignore[attr-defined]
                    found.append((method, route, f"{path.relative_to(SRC)}:{node.lineno}"))
    return found


def scripts() -> list[Path]:
    return sorted(p for p in STATIC.rglob("*.js") if "vendor" not in p.parts)


def test_every_http_route_is_a_page_a_schema_or_a_file():
    routes = literal_routes()
    assert len(routes) >= 10, "the scan must find the web tools' routes"
    unknown = [f"{m} {r} ({where})" for m, r, where in routes if (m, r) not in ALLOWED_ROUTES]
    assert unknown == [], "live data goes through the gateway; new routes: " + ", ".join(unknown)


def test_no_server_sent_events_anywhere():
    for path in [*SRC.rglob("*.py"), *scripts()]:
        text = path.read_text(encoding="utf-8")
        assert "text/event-stream" not in text and "EventSource" not in text, path


def test_only_the_gateway_client_opens_a_websocket():
    opening = [p.relative_to(STATIC).as_posix() for p in scripts() if "new WebSocket" in p.read_text()]
    assert opening == ["lib/rosclient.js"]


def test_the_live_pages_fetch_no_data_over_http():
    """The graph page and the simulators' views draw only what the gateway sends them."""
    for name in ("graph.js", "turtlesim.js", "puzzlebot.js"):
        text = (STATIC / name).read_text(encoding="utf-8")
        assert not re.search(r"\bfetch\(|XMLHttpRequest|getJson\(", text), name
        assert "rosclient" in text, f"{name} gets its data through lib/rosclient.js"
