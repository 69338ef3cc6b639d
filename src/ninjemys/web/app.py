"""The web tools app: one HTTP server, one static front end, pages that plug in.

The node graph is always there (it is the first page); other tools add pages and API routes, e.g. the
turtlesim node adds its live view (:mod:`ninjemys.web.turtlesim_view`). The app runs its server on its own
event loop thread by default, or on a loop the caller already runs (:meth:`WebApp.start_on`).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class
from ninjemys.serve.events import Hub
from ninjemys.serve.http import HttpError, HttpServer, Request, Response
from ninjemys.web.graph import GraphPoller
from ninjemys.web.monitor import TopicMonitor

if TYPE_CHECKING:
    from ninjemys.bridge.server import Gateway

log = logging.getLogger(__name__)

STATIC_DIR = Path(__file__).parent / "static"


@dataclass(frozen=True)
class Page:
    """An entry of the navigation bar."""

    title: str
    path: str


def _message_definition(request: Request) -> Response:
    """``GET /api/msgdef?type=pkg/Type``: the full ros1msg text, for a page that publishes a type
    no channel advertises yet (the browser's ROS client serializes from it)."""
    type_name = request.arg("type")
    if not type_name:
        raise HttpError(400, "missing ?type=pkg/Type")
    try:
        msg_class = get_message_class(type_name)
    except NinjemysError as exc:
        raise HttpError(404, str(exc)) from exc
    return Response({"type": type_name, "definition": msg_class._full_text})


class WebApp:
    """The web tools server for one ROS graph.

    ``monitor`` (optional) adds live rate and last message to the topic details
    (:class:`ninjemys.web.monitor.TopicMonitor`); without it the details are what the master knows.
    """

    def __init__(
        self,
        master_uri: str,
        caller_id: str = "/rqt_graph",
        host: str = "127.0.0.1",
        port: int = 0,
        poll_period: float = 0.5,
        monitor: TopicMonitor | None = None,
    ) -> None:
        self.master_uri = master_uri
        self.caller_id = caller_id
        self.server = HttpServer(host, port)
        self.pages: list[Page] = [Page("Node graph", "/")]
        self.monitor = monitor
        self.loop: asyncio.AbstractEventLoop | None = None
        self.graph_hub: Hub | None = None
        self._poll_period = poll_period
        self._poller: GraphPoller | None = None
        self._thread: threading.Thread | None = None
        self._started = threading.Event()
        self._start_error: BaseException | None = None
        self._master_error: str | None = None
        self._routes()

    @property
    def url(self) -> str:
        return self.server.url

    def add_page(self, title: str, path: str) -> None:
        self.pages.append(Page(title, path))

    def add_gateway(self, gateway: Gateway, path: str = "/ws") -> None:
        """Serve a started :class:`ninjemys.bridge.server.Gateway` on this app's server at ``path``
        (``ws://<app>/ws``): the pages' one data path (Foxglove subprotocol: raw ROS 1 bytes and the
        definitions to decode them), and rosbridge for roslibjs pages. Call before :meth:`start`."""
        gateway.mount(self.server, path)
        self.server.route("GET", "/api/msgdef", _message_definition)

    def hub(self) -> Hub:
        """A new event hub on the app's loop (call after start)."""
        if self.loop is None:
            raise RuntimeError("WebApp.hub() needs a started app")
        return Hub(self.loop)

    # -- routes ------------------------------------------------------------------------------
    def _routes(self) -> None:
        s = self.server
        s.static("/static", STATIC_DIR)
        s.route("GET", "/", lambda _r: self._static_page("graph.html"))
        s.route("GET", "/graph", lambda _r: self._static_page("graph.html"))
        s.route("GET", "/api/pages", lambda _r: Response([p.__dict__ for p in self.pages]))
        s.route("GET", "/api/graph", self._get_graph)
        s.route("GET", "/api/graph/events", self._graph_events)
        s.route("POST", "/api/graph/refresh", self._refresh)
        s.route("GET", "/api/topic", self._get_topic)

    def _static_page(self, name: str) -> Response:
        return Response((STATIC_DIR / name).read_bytes(), 200, "text/html; charset=utf-8")

    def _graph_state(self) -> dict:
        graph = self._poller.graph if self._poller is not None else None
        return {"graph": graph, "master_uri": self.master_uri, "error": self._master_error}

    def _get_graph(self, _request: Request) -> Response:
        return Response(self._graph_state())

    def _graph_events(self, _request: Request):  # type: ignore[no-untyped-def]
        assert self.graph_hub is not None
        return self.graph_hub.open([("state", self._graph_state())])

    def _refresh(self, _request: Request) -> Response:
        if self._poller is not None:
            self._poller.refresh()
        return Response({"ok": True})

    async def _get_topic(self, request: Request) -> Response:
        name = request.arg("name")
        if not name:
            raise HttpError(400, "missing ?name=<topic>")
        graph = self._poller.graph if self._poller is not None else None
        topic = next((t for t in (graph or {}).get("topics", []) if t["name"] == name), None)
        if topic is None:
            raise HttpError(404, f"topic {name} is not in the graph")
        details = dict(topic)
        if self.monitor is not None:
            # subscribing talks to the master and the publishers: keep it off the event loop
            loop = asyncio.get_running_loop()
            try:
                details.update(await loop.run_in_executor(None, self.monitor.info, name, topic["type"]))
            except NinjemysError as exc:  # monitoring is best effort; the master's facts still show
                details["monitor_error"] = str(exc)
        return Response(details)

    # -- graph polling -----------------------------------------------------------------------
    def _on_graph(self, graph: dict) -> None:
        self._master_error = None
        if self.graph_hub is not None:
            self.graph_hub.publish("state", self._graph_state(), resync=self._graph_state)

    def _on_master_error(self, message: str) -> None:
        self._master_error = message
        if self.graph_hub is not None:
            self.graph_hub.publish("state", self._graph_state(), resync=self._graph_state)

    # -- lifecycle ---------------------------------------------------------------------------
    async def start_on(self) -> None:
        """Start serving on the running loop (and the graph poller on its thread)."""
        self.loop = asyncio.get_running_loop()
        self.graph_hub = Hub(self.loop)
        await self.server.start()
        self._poller = GraphPoller(
            self.master_uri,
            self.caller_id,
            self._on_graph,
            self._on_master_error,
            own_nodes=self.monitor.node_names if self.monitor is not None else frozenset,
            period=self._poll_period,
        )
        self._poller.start()

    def start(self) -> str:
        """Start on a dedicated event-loop thread; returns the URL once the port is bound."""
        self._thread = threading.Thread(target=self._run_loop, name="web-tools", daemon=True)
        self._thread.start()
        self._started.wait(10.0)
        if self._start_error is not None:
            raise self._start_error
        return self.url

    def _run_loop(self) -> None:
        loop = asyncio.new_event_loop()
        try:
            loop.run_until_complete(self.start_on())
        except BaseException as exc:  # e.g. port in use: reported to start()
            self._start_error = exc
            self._started.set()
            loop.close()
            return
        self._started.set()
        try:
            loop.run_forever()
        finally:
            with contextlib.suppress(Exception):
                loop.run_until_complete(self.server.close())
            loop.close()

    def stop(self) -> None:
        """Stop polling and serving; joins the loop thread when the app owns it."""
        if self._poller is not None:
            self._poller.stop()
        if self.monitor is not None:
            self.monitor.close()
        if self.graph_hub is not None:
            self.graph_hub.close()
        loop = self.loop
        if self._thread is not None and loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(loop.stop)
            self._thread.join(5.0)
        elif loop is not None and not loop.is_closed():
            asyncio.run_coroutine_threadsafe(self.server.close(), loop)
