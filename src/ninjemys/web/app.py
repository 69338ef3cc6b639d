"""The web tools app: one HTTP server, one static front end, pages that plug in.

The node graph is always there (it is the first page); other tools add pages, e.g. the turtlesim
node adds its live view (:mod:`ninjemys.web.turtlesim_view`). Every page gets its data the same way,
through the gateway mounted on this server (:meth:`WebApp.add_gateway`, ``ws://<app>/ws``): the
graph page from its connection graph, the others from topics, services and app channels. The app
serves files and little else. It runs its server on its own event loop thread by default, or on a
loop the caller already runs (:meth:`WebApp.start_on`).
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
from ninjemys.serve.http import HttpError, HttpServer, Request, Response
from ninjemys.web import resources

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
    """The web tools server for one ROS graph (``master_uri``); pages need a gateway mounted on it."""

    def __init__(
        self, master_uri: str, caller_id: str = "/rqt_graph", host: str = "127.0.0.1", port: int = 0
    ) -> None:
        self.master_uri = master_uri
        self.caller_id = caller_id
        self.server = HttpServer(host, port)
        self.pages: list[Page] = [Page("Node graph", "/")]
        self.loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._started = threading.Event()
        self._start_error: BaseException | None = None
        self._routes()

    @property
    def url(self) -> str:
        return self.server.url

    def add_page(self, title: str, path: str) -> None:
        self.pages.append(Page(title, path))

    def add_gateway(self, gateway: Gateway, path: str = "/ws") -> None:
        """Serve a started :class:`ninjemys.bridge.server.Gateway` on this app's server at ``path``
        (``ws://<app>/ws``): the pages' one data path (Foxglove subprotocol: raw ROS 1 bytes and the
        definitions to decode them, the connection graph, app channels), and rosbridge for roslibjs
        pages. Before or after :meth:`start` (routes are looked up per request)."""
        gateway.mount(self.server, path)
        self.server.route("GET", "/api/msgdef", _message_definition)

    # -- routes ------------------------------------------------------------------------------
    def _routes(self) -> None:
        s = self.server
        s.static("/static", STATIC_DIR)
        s.route("GET", "/", lambda _r: self._static_page("graph.html"))
        s.route("GET", "/graph", lambda _r: self._static_page("graph.html"))
        s.route("GET", "/api/pages", lambda _r: Response([p.__dict__ for p in self.pages]))
        # mesh files of robot descriptions (package://, file://), for rviz's RobotModel
        s.route("GET", resources.ROUTE, resources.Resources().handle)

    def _static_page(self, name: str) -> Response:
        return Response((STATIC_DIR / name).read_bytes(), 200, "text/html; charset=utf-8")

    # -- lifecycle ---------------------------------------------------------------------------
    async def start_on(self) -> None:
        """Start serving on the running loop."""
        self.loop = asyncio.get_running_loop()
        await self.server.start()

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
        """Stop serving; joins the loop thread when the app owns it."""
        loop = self.loop
        if self._thread is not None and loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(loop.stop)
            self._thread.join(5.0)
        elif loop is not None and not loop.is_closed():
            asyncio.run_coroutine_threadsafe(self.server.close(), loop)
