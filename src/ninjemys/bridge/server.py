"""The gateway: one WebSocket endpoint speaking rosbridge v2 and Foxglove, on the web tools' HTTP server.

A client that offers a Foxglove subprotocol (``foxglove.websocket.v1``, ``foxglove.sdk.v1``) gets
the Foxglove protocol; any other client (roslibjs, roslibpy: no subprotocol) gets rosbridge. So one
port serves both, and the same server serves the static web app (:class:`Gateway.mount` puts the
endpoint on any :class:`ninjemys.serve.http.HttpServer`).

Per client: a :class:`~ninjemys.bridge.outbox.Outbox` (bounded, per-topic lanes, fair) filled by
ROS threads, and one sender task on the event loop that moves it into the socket only as fast as
the client reads (the transport buffer is capped; see :mod:`ninjemys.serve.websocket`). A client that
stops reading costs at most its budget; the ROS side and the other clients never wait for it.
"""

from __future__ import annotations

import asyncio
import hmac
import itertools
import json
import logging
import ssl
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from websockets.server import ServerProtocol

from ninjemys.bridge.appchannels import AppChannel
from ninjemys.bridge.buswatch import BusWatch
from ninjemys.bridge.foxglove import SUBPROTOCOLS, FoxgloveSession
from ninjemys.bridge.graph import Publishers, Services, Taps
from ninjemys.bridge.outbox import CloseRequest, Outbox
from ninjemys.bridge.rosbridge import RosbridgeSession
from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.master.snapshot import GraphSnapshot
from ninjemys.net import auth
from ninjemys.node import Node
from ninjemys.serve.http import HttpServer, Request, Response
from ninjemys.serve.websocket import WRITE_HIGH_WATER, WebSocket

log = logging.getLogger(__name__)

_LOCAL_HOSTS = {"localhost", "127.0.0.1", "::1", "[::1]"}
#: frames are written to the socket in batches of about this size (or when the outbox is empty)
_BATCH_BYTES = 64 * 1024


@dataclass
class GatewayOptions:
    """What the launch files' arguments set (names follow rosbridge_websocket.launch / foxglove_bridge.launch)."""

    address: str = "127.0.0.1"
    port: int = 9090
    certfile: str | None = None
    keyfile: str | None = None
    #: rosbridge ``auth`` op required first (rosauth MAC); Foxglove clients need ``token``
    authenticate: bool = False
    #: rosauth's shared secret (the file's text, stripped); also the Foxglove token unless ``token`` is set
    secret_file: str | None = None
    token: str | None = None
    auth_time_delta: float = 5.0
    #: allowed browser Origins; empty: pages served by this host and localhost pages only
    origins: list[str] = field(default_factory=list)
    #: largest message a client may send (bytes); a larger frame gets a status error and a 1009 close
    max_message_size: int = 10 * 1024 * 1024
    #: queued data per client before the oldest topic data is dropped (bytes)
    max_client_bytes: int = 8 * 1024 * 1024
    #: Foxglove lanes: messages kept per client and channel
    queue_length: int = 10
    #: bytes sent to a client and not yet confirmed read (WebSocket ping/pong) before the gateway waits
    #: for it, so that a slow client's backlog stays in its outbox, where the oldest data is dropped,
    #: instead of in the sockets' buffers, where it is only late (0: no limit; see WebSocket.pace)
    client_window: int = 1024 * 1024
    #: how often the topic and service lists are refreshed (s)
    update_period: float = 1.0
    node_name: str = "rosbridge_websocket"
    protocols: tuple[str, ...] = ("rosbridge", "foxglove")
    #: publish the number of connected clients on ``client_count`` (latched), as rosbridge_websocket does
    client_count: bool = False
    #: a service call not answered within this many seconds gets a failed reply (rosbridge's
    #: ``default_call_service_timeout``; a rosbridge call's own ``timeout`` field overrides it)
    call_service_timeout: float = 5.0
    #: a folder the standalone server (:meth:`Gateway.run_in_thread`) serves at ``/static`` (e.g. the
    #: web app's pages and scripts); None serves no files. The gateway does not know the web app:
    #: the web app sits above it and passes its folder in.
    static_dir: str | None = None
    #: the gateway's node exists only to look at the graph (rqt_graph): the graph page counts it as
    #: debug plumbing ("Hide debug"), so looking at a topic does not change the picture
    hide_own_node: bool = False
    #: under /use_sim_time, follow /clock (the ``time`` capability, sim-time receive stamps); a gateway
    #: inside the simulator itself sets False: its pages need no clock, and subscribing to its own
    #: /clock would decode every tick in the simulator's process
    sim_clock: bool = True

    def secret(self) -> str | None:
        if not self.authenticate:
            return None
        if self.secret_file is None:
            # the graph's own credentials (ninjemys.net.auth): NINJEMYS_SECRET / NINJEMYS_SECRET_FILE, or
            # with per-node keys the key of the gateway's node (NINJEMYS_KEY, or its NINJEMYS_KEYS_FILE line)
            creds = auth.credentials()
            name = self.node_name if self.node_name.startswith("/") else f"/{self.node_name}"
            key = None if creds is None else creds.secret_for(name)
            if key is None:
                raise NinjemysError(
                    "authentication is on but no secret is set (secret_file, or NINJEMYS_SECRET for the "
                    f"graph's, or a key for {name} in NINJEMYS_KEYS_FILE)"
                )
            return key.decode("utf-8", "replace")
        return Path(self.secret_file).read_text().strip()

    def foxglove_token(self) -> str | None:
        if not self.authenticate:
            return None
        return self.token if self.token is not None else self.secret()

    def ssl_context(self) -> ssl.SSLContext | None:
        if not self.certfile:
            return None
        ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
        ctx.load_cert_chain(self.certfile, self.keyfile or None)
        return ctx


class Catalog:
    """The topics (Foxglove channels), services and connection graph, refreshed from the master."""

    def __init__(self) -> None:
        self.channels: dict[int, dict[str, Any]] = {}
        self.services: dict[int, dict[str, Any]] = {}
        self._channel_ids: dict[tuple[str, str], int] = {}
        self._service_ids: dict[tuple[str, str], int] = {}
        self._ids = itertools.count(1)
        self._unknown: set[str] = set()
        self._service_types: dict[str, str] = {}
        #: the graph as of the last refresh (the one snapshot type every graph reader uses)
        self.snapshot = GraphSnapshot()
        #: channels an in-process app publishes (not ROS topics): id -> channel; never refreshed away
        self.app: dict[int, AppChannel] = {}
        self._lock = threading.Lock()

    def channel(self, channel_id: int) -> dict[str, Any] | None:
        return self.channels.get(channel_id)

    def add_app_channel(
        self, topic: str, schema_name: str, snapshot: Callable[[], Any] | None, lock: Any
    ) -> AppChannel:
        app = AppChannel(next(self._ids), topic, schema_name, snapshot, lock)
        with self._lock:
            self.app[app.id] = app
            self.channels[app.id] = app.channel
        return app

    def refresh(
        self,
        node: Node,
        services: Services,
        learn: Callable[[str, str], str | None] = lambda t, n: None,
        probe: bool = True,
    ) -> dict[str, Any]:
        """Poll the master; returns what changed: added/removed channels and services, graph diff.

        ``learn(topic, type)`` gives the definition text of a type the gateway cannot load (as a
        publisher sent it), or None while it is not known yet. ``probe=False`` leaves out the services
        whose type is not known yet (a later refresh probes them): each probe is a lookup and a
        connection to its provider, and every node has two services (get_loggers, set_logger_level)."""
        snapshot = GraphSnapshot.fetch(node.master, published=False)
        types, pubs, srvs = snapshot.topic_types, snapshot.publishers, snapshot.services
        added, removed = [], []
        wanted: dict[tuple[str, str], None] = {}
        for topic in pubs:
            type_name = types.get(topic)
            if not type_name or type_name == "*":
                continue
            try:
                schema = get_message_class(type_name)._full_text
            except NinjemysError as exc:
                learned = learn(topic, type_name)
                if learned is None:
                    if type_name not in self._unknown:
                        self._unknown.add(type_name)
                        log.info("gateway: %s (%s): waiting for its definition from a publisher", topic, exc)
                    continue
                schema = learned
            key = (topic, type_name)
            wanted[key] = None
            if key not in self._channel_ids:
                cid = next(self._ids)
                channel = {
                    "id": cid,
                    "topic": topic,
                    "encoding": "ros1",
                    "schemaName": type_name,
                    "schema": schema,
                    "schemaEncoding": "ros1msg",
                }
                with self._lock:
                    self._channel_ids[key] = cid
                    self.channels[cid] = channel
                added.append(channel)
        for key in [k for k in self._channel_ids if k not in wanted]:
            with self._lock:
                cid = self._channel_ids.pop(key)
                self.channels.pop(cid, None)
            removed.append(cid)
        added_srv, removed_srv = [], []
        present = set()
        for name in srvs:
            # a provider's type is probed once per service name, not on every refresh
            type_name = self._service_types.get(name)
            if type_name is None and not probe:
                continue
            try:
                if type_name is None:
                    type_name = self._service_types[name] = services.service_type(name)
                service_class = get_service_class(type_name)
            except NinjemysError:
                continue
            key = (name, type_name)
            present.add(key)
            if key not in self._service_ids:
                sid = next(self._ids)
                req, resp = service_class._request_class, service_class._response_class
                entry = {
                    "id": sid,
                    "name": name,
                    "type": type_name,
                    "requestSchema": req._full_text,
                    "responseSchema": resp._full_text,
                    "request": {
                        "encoding": "ros1",
                        "schemaName": req._type,
                        "schemaEncoding": "ros1msg",
                        "schema": req._full_text,
                    },
                    "response": {
                        "encoding": "ros1",
                        "schemaName": resp._type,
                        "schemaEncoding": "ros1msg",
                        "schema": resp._full_text,
                    },
                }
                with self._lock:
                    self._service_ids[key] = sid
                    self.services[sid] = entry
                added_srv.append(entry)
        for name in [n for n in self._service_types if n not in srvs]:
            del self._service_types[name]
        for key in [k for k in self._service_ids if k not in present]:
            with self._lock:
                sid = self._service_ids.pop(key)
                self.services.pop(sid, None)
            removed_srv.append(sid)
        old, self.snapshot = self.snapshot, snapshot
        return {
            "channels": added,
            "removed_channels": removed,
            "services": added_srv,
            "removed_services": removed_srv,
            "graph_changed": not old.same_graph(snapshot),
            "old_graph": old,
        }

    @property
    def topic_types(self) -> Mapping[str, str]:
        """getTopicTypes as of the last refresh."""
        return self.snapshot.topic_types

    @property
    def graph(self) -> dict[str, dict[str, list[str]]]:
        """The last snapshot as the connection graph shows it: name -> sorted node names."""
        return _graph_view(self.snapshot)

    def node_names(self) -> set[str]:
        """Every node the master lists as a publisher, subscriber or service provider."""
        return set(self.snapshot.node_names())

    @staticmethod
    def bus_update(state: dict[str, Any]) -> dict[str, Any]:
        """A connectionGraphUpdate carrying only the bus state (ninjemys' ``rosBus`` extension:
        node liveness and live connections from getBusInfo; Foxglove clients ignore it)."""
        return {
            "op": "connectionGraphUpdate",
            "publishedTopics": [],
            "subscribedTopics": [],
            "advertisedServices": [],
            "removedTopics": [],
            "removedServices": [],
            "rosBus": state,
        }

    def graph_update(self, full: bool, old: GraphSnapshot | None = None) -> dict[str, Any]:
        """A connectionGraphUpdate: everything (``full``) or what changed since ``old``."""
        g = self.graph
        old_view = _graph_view(old if old is not None and not full else GraphSnapshot())
        return _graph_diff(g, old_view)


def _graph_view(snapshot: GraphSnapshot) -> dict[str, dict[str, list[str]]]:
    return {
        kind: {name: sorted(nodes) for name, nodes in table.items()}
        for kind, table in (
            ("pub", snapshot.publishers),
            ("sub", snapshot.subscribers),
            ("srv", snapshot.services),
        )
    }


def _graph_diff(g: dict[str, dict[str, list[str]]], old: dict[str, dict[str, list[str]]]) -> dict[str, Any]:
    """Foxglove's connectionGraphUpdate from graph view ``old`` to ``g``."""
    gone = (set(old["pub"]) | set(old["sub"])) - (set(g["pub"]) | set(g["sub"]))

    def changed(kind: str) -> list[str]:
        # a topic that lost its last publisher (or subscriber) but still exists is listed with no
        # ids; one that left altogether is in removedTopics
        now = [k for k, v in g[kind].items() if old[kind].get(k) != v]
        emptied = [k for k in old[kind] if k not in g[kind] and k not in gone]
        return now + emptied

    return {
        "op": "connectionGraphUpdate",
        "publishedTopics": [{"name": t, "publisherIds": g["pub"].get(t, [])} for t in changed("pub")],
        "subscribedTopics": [{"name": t, "subscriberIds": g["sub"].get(t, [])} for t in changed("sub")],
        "advertisedServices": [
            {"name": s, "providerIds": g["srv"][s]} for s in g["srv"] if old["srv"].get(s) != g["srv"][s]
        ],
        "removedTopics": sorted(gone),
        "removedServices": sorted(set(old["srv"]) - set(g["srv"])),
    }


class _Client:
    """One connection: its protocol session, outbox and sender task."""

    def __init__(
        self, client_id: int, ws: WebSocket, loop: asyncio.AbstractEventLoop, max_bytes: int
    ) -> None:
        self.id = client_id
        self.ws = ws
        self.loop = loop
        self.wake = asyncio.Event()
        self.outbox = Outbox(max_bytes, self._wake_threadsafe)
        self.session: RosbridgeSession | FoxgloveSession | None = None
        self.reported: dict[str, int] = {}

    def _wake_threadsafe(self) -> None:
        try:
            self.loop.call_soon_threadsafe(self.wake.set)
        except RuntimeError:  # the loop is gone: the client is being torn down
            pass


class Gateway:
    """The gateway's node and its WebSocket endpoint; see the module docstring."""

    def __init__(self, options: GatewayOptions | None = None, node: Node | None = None) -> None:
        self.options = options or GatewayOptions()
        self.node = node if node is not None else Node(self.options.node_name)
        self._own_node = node is None
        self.catalog = Catalog()
        self.sim_time = self.options.sim_clock and bool(self._param("/use_sim_time", False))
        self.taps = Taps(self.node, self._now_ns)
        self.publishers = Publishers(self.node)
        self.services = Services(self.node)
        self.pool = ThreadPoolExecutor(8, thread_name_prefix="gateway")
        #: node liveness and live connections (getBusInfo), swept only while a client watches the graph
        self.bus = BusWatch(self.node.master, self.node.name, self.pool, self._bus_changed)
        self.master_error: str | None = None
        self.session_id = str(time.time_ns())
        self._clients: dict[int, _Client] = {}
        self._ids = itertools.count(1)
        self._stop = threading.Event()
        self._sim_ns = 0
        self._watched: set[str] = set()
        self._watch_lock = threading.Lock()
        self._definitions: dict[str, str] = {}
        self._probing: set[tuple[str, str]] = set()
        self._refresh_failing = False
        self._clock_sub: Any = None
        self._client_count: Any = None
        self._poller = threading.Thread(target=self._poll, name="gateway-graph", daemon=True)
        self._http: HttpServer | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._reporter: asyncio.Task[None] | None = None

    def _param(self, key: str, default: Any) -> Any:
        try:
            return self.node.get_param(key, default)
        except NinjemysError:
            return default

    def _now_ns(self) -> int:
        return self._sim_ns if self.sim_time else time.time_ns()

    def topic_type(self, topic: str) -> str | None:
        known = self.catalog.topic_types.get(topic)
        if known:
            return known
        try:
            return dict(self.node.master.get_topic_types()).get(topic)
        except NinjemysError:
            return None

    def app_channel(
        self, topic: str, schema_name: str, snapshot: Callable[[], Any] | None = None, lock: Any = None
    ) -> AppChannel:
        """A JSON channel this process publishes on the gateway (not a ROS topic; see
        :mod:`ninjemys.bridge.appchannels`), advertised to the Foxglove clients at once."""
        app = self.catalog.add_app_channel(topic, schema_name, snapshot, lock)
        for client in list(self._clients.values()):
            if isinstance(client.session, FoxgloveSession):
                client.session.send({"op": "advertise", "channels": [app.channel]})
        return app

    # -- graph polling ----------------------------------------------------------------------
    def start(self) -> None:
        """Start watching the graph (and /clock under sim time); publish ``client_count`` if asked."""
        if self.options.client_count:
            self._client_count = self.node.publisher(
                "client_count", get_message_class("std_msgs/Int32"), queue_size=1, latch=True
            )
            self._count_clients()
        if self.sim_time:
            self._clock_sub = self.node.subscriber(
                "/clock", get_message_class("rosgraph_msgs/Clock"), self._on_clock, queue_size=1
            )
        # the graph and the topics at once; the services' types from the poller's first round (probing
        # them one by one held the first 100-node graph back by 200-300 ms)
        self._refresh(probe=False)
        self._poller.start()

    def _count_clients(self) -> None:
        if self._client_count is not None:
            self._client_count.publish(get_message_class("std_msgs/Int32")(data=len(self._clients)))

    def _on_clock(self, msg: Any) -> None:
        self._sim_ns = msg.clock.secs * 1_000_000_000 + msg.clock.nsecs
        for client in list(self._clients.values()):
            if isinstance(client.session, FoxgloveSession):
                client.session.send_time(self._sim_ns)

    def _poll(self) -> None:
        self._refresh()
        while not self._stop.wait(self.options.update_period):
            self._refresh()

    def _learn(self, topic: str, type_name: str) -> str | None:
        """The definition of a type we cannot load, from a publisher's connection header: a raw
        subscription (md5 ``*``) takes one message, keeps its ``message_definition`` and leaves."""
        known = self._definitions.get(type_name)
        if known is not None or (topic, type_name) in self._probing:
            return known
        self._probing.add((topic, type_name))
        owner = ("definition probe", topic)

        def sink(d: Any) -> None:
            text = d.header.get("message_definition")
            if text and d.header.get("type") == type_name:
                self._definitions.setdefault(type_name, text)
            # unsubscribing joins the subscription's thread: not from inside its own callback
            self.pool.submit(self.taps.remove, topic, owner)

        try:
            self.taps.add(topic, type_name, owner, sink, published_as=type_name)
        except NinjemysError as exc:
            log.warning("gateway: cannot learn the definition of %s on %s: %s", type_name, topic, exc)
        return None

    def _refresh(self, probe: bool = True) -> None:
        try:
            diff = self.catalog.refresh(self.node, self.services, self._learn, probe)
        except NinjemysError as exc:
            # once per outage (a dead master fails every refresh), then once more when it is back
            if not self._refresh_failing:
                log.warning(
                    "gateway: graph refresh failed (retrying every %g s): %s", self.options.update_period, exc
                )
                self._refresh_failing = True
                self.master_error = f"cannot reach the master at {self.node.master_uri}: {exc}"
                for fox in self._foxes():
                    fox.master_status(self.master_error)
            return
        foxes = self._foxes()
        if self._refresh_failing:
            log.info("gateway: graph refresh works again")
            self._refresh_failing = False
            self.master_error = None
            for fox in foxes:
                fox.master_status(None)
        for fox in foxes:
            if diff["removed_channels"]:
                fox.channels_removed(diff["removed_channels"])
                fox.send({"op": "unadvertise", "channelIds": diff["removed_channels"]})
            if diff["channels"]:
                fox.send({"op": "advertise", "channels": diff["channels"]})
            if diff["removed_services"]:
                fox.send({"op": "unadvertiseServices", "serviceIds": diff["removed_services"]})
            if diff["services"]:
                fox.send({"op": "advertiseServices", "services": diff["services"]})
            if diff["graph_changed"] and fox.graph_subscribed:
                fox.send(self.catalog.graph_update(full=False, old=diff["old_graph"]))
        if any(fox.graph_subscribed for fox in foxes):
            self.bus.poke(self.catalog.node_names())

    def _foxes(self) -> list[FoxgloveSession]:
        return [c.session for c in list(self._clients.values()) if isinstance(c.session, FoxgloveSession)]

    def _bus_changed(self, state: dict[str, Any]) -> None:
        update = self.catalog.bus_update(state)
        for fox in self._foxes():
            if fox.graph_subscribed:
                fox.send(update)

    def graph_update(self) -> dict[str, Any]:
        """The full connection graph for a client that just subscribed, with the bus state so far
        (call :meth:`sweep_bus` once it is sent: the sweep's result follows as an update)."""
        update = self.catalog.graph_update(full=True)
        update["rosBus"] = self.bus.state()
        return update

    def sweep_bus(self) -> None:
        """Ask every node for its connections now. Started after the graph is on its way, so that
        a hundred getBusInfo calls do not hold up the first picture of the graph."""
        self.bus.poke(self.catalog.node_names(), force=True)

    def watch_param(self, name: str) -> None:
        """Forward master paramUpdate for ``name`` to the Foxglove clients that subscribed it."""
        with self._watch_lock:
            if name in self._watched:
                return
            # marked only once the master has the subscription: a change right after a client's
            # subscribeParameterUpdates was answered must reach it
            self.node.subscribe_param(name, self._param_changed)
            self._watched.add(name)

    def _param_changed(self, key: str, value: Any) -> None:
        name = key.rstrip("/") or "/"
        for client in list(self._clients.values()):
            if isinstance(client.session, FoxgloveSession):
                client.session.param_changed(name, value)

    # -- the WebSocket endpoint ---------------------------------------------------------------
    def mount(self, server: HttpServer, path: str = "/") -> None:
        """Serve the gateway on ``server`` at ``path`` (plus its status at /api/bridge/status).

        Call :meth:`start` too (graph polling); the server's own loop then runs the connections."""
        server.websocket(path, self)
        server.route("GET", "/api/bridge/status", lambda _r: Response(self.status()))

    def handshake(self, request: Request) -> ServerProtocol | tuple[int, str]:
        offered = [
            p.strip() for p in request.headers.get("sec-websocket-protocol", "").split(",") if p.strip()
        ]
        foxglove = any(p in SUBPROTOCOLS for p in offered)
        kind = "foxglove" if foxglove else "rosbridge"
        if kind not in self.options.protocols:
            return (400, f"this server does not speak {kind}")
        origin = request.headers.get("origin")
        if origin is not None and not self._origin_ok(origin, request.headers.get("host", "")):
            return (403, f"origin {origin} is not allowed (see the origins option)")
        if foxglove:
            token = self.options.foxglove_token()
            if token is not None:
                given = request.arg("token") or ""
                auth = request.headers.get("authorization", "")
                if auth.lower().startswith("bearer "):
                    given = auth[7:].strip()
                if not hmac.compare_digest(given.encode(), token.encode()):
                    return (401, "a valid token is required (?token=... or Authorization: Bearer ...)")

        def select(_protocol: ServerProtocol, subprotocols: Any) -> Any:
            for p in subprotocols:
                if p in SUBPROTOCOLS:
                    return p
            return None

        return ServerProtocol(select_subprotocol=select, max_size=self.options.max_message_size)

    def _origin_ok(self, origin: str, host: str) -> bool:
        allowed = self.options.origins
        if "*" in allowed or origin in allowed:
            return True
        if allowed:
            return False
        origin_host = urlsplit(origin).hostname or ""
        own_host = urlsplit("//" + host).hostname or ""
        return origin_host in _LOCAL_HOSTS or origin_host == own_host

    async def serve(self, ws: WebSocket) -> None:
        loop = asyncio.get_running_loop()
        self._loop = self._loop or loop  # whichever server's loop the gateway is mounted on
        if self._reporter is None:  # runs while clients are connected (see the end of serve)
            self._reporter = loop.create_task(self._report_drops())
        client = _Client(next(self._ids), ws, loop, self.options.max_client_bytes)
        if ws.subprotocol in SUBPROTOCOLS:
            session: RosbridgeSession | FoxgloveSession = FoxgloveSession(self, client.id, client.outbox)
            ws.on_oversized = lambda why: json.dumps(
                {"op": "status", "level": 2, "message": f"message too big: {why}"}
            )
        else:
            session = RosbridgeSession(self, client.id, client.outbox)
            ws.on_oversized = lambda why: json.dumps(
                {"op": "status", "level": "error", "msg": f"message too big: {why}"}
            )
        client.session = session
        self._clients[client.id] = client
        self._count_clients()
        log.info(
            "gateway: client %d (%s) connected from %s", client.id, ws.subprotocol or "rosbridge", ws.peer
        )
        if isinstance(session, FoxgloveSession):
            session.hello()
        session.backlog.bind(loop, asyncio.Event())
        sender = asyncio.create_task(self._sender(client))
        try:
            async for data in ws.messages():
                session.receive(data)
                await session.backlog.wait()
        finally:
            # the tasks this connection started end before it does, so a server closing its
            # connections leaves nothing pending on the loop
            sender.cancel()
            self._clients.pop(client.id, None)
            reporter = self._reporter if not self._clients else None
            if reporter is not None:
                self._reporter = None
                reporter.cancel()
            self._count_clients()
            session.close()
            log.info("gateway: client %d disconnected", client.id)
            await asyncio.gather(sender, *([reporter] if reporter else []), return_exceptions=True)

    async def _sender(self, client: _Client) -> None:
        ws, outbox = client.ws, client.outbox
        limit = self.options.max_client_bytes
        window = self.options.client_window
        try:
            while not ws.closed:
                await client.wake.wait()
                client.wake.clear()
                pending = 0  # bytes framed but not yet written: a burst leaves in one write
                while (item := outbox.take()) is not None:
                    if isinstance(item, CloseRequest):
                        ws.flush()
                        ws.close(item.code, item.reason)
                        return
                    for frame in item if isinstance(item, tuple) else (item,):
                        ws.send(frame, flush=False)
                        pending += len(frame)
                    if pending >= _BATCH_BYTES:
                        ws.flush()
                        pending = 0
                        if ws.buffered > WRITE_HIGH_WATER:
                            await ws.drain()
                        if window:
                            await ws.pace(window)  # what comes meanwhile waits (and drops) in the outbox
                    if outbox.bytes > 4 * limit:  # replies pile up: the client is not reading at all
                        ws.close(1008, "client too slow: its replies exceed the memory budget")
                        return
                ws.flush()
                if window:
                    await ws.pace(window)
        except (ConnectionError, asyncio.CancelledError):
            return

    def close_client(self, client_id: int, code: int, reason: str) -> None:
        """Close a client's connection once what was queued for it before is sent."""
        client = self._clients.get(client_id)
        if client is not None:
            client.outbox.put_control(CloseRequest(code, reason))

    async def _report_drops(self) -> None:
        """Once a second, tell each client about data dropped for it since the last report."""
        while True:
            await asyncio.sleep(1.0)
            for client in list(self._clients.values()):
                for lane, count in list(client.outbox.dropped.items()):
                    new = count - client.reported.get(lane, 0)
                    if new <= 0 or lane.startswith("\0"):
                        continue
                    client.reported[lane] = count
                    topic = lane.split("#", 1)[0]
                    text = f"dropped {new} messages on {topic} (client reads too slowly; {count} in all)"
                    if isinstance(client.session, FoxgloveSession):
                        client.session.status(1, text)
                    elif isinstance(client.session, RosbridgeSession):
                        client.session.status("warning", text)

    def status(self) -> dict[str, Any]:
        """Per client: protocol, queued bytes, bytes sent but not yet confirmed read (in the sockets'
        buffers or the client's) and drops per topic (GET /api/bridge/status)."""
        return {
            "clients": [
                {
                    "id": c.id,
                    "protocol": c.ws.subprotocol or "rosbridge",
                    "peer": c.ws.peer,
                    "queued_bytes": c.outbox.bytes,
                    "unconfirmed_bytes": c.ws.sent - c.ws.confirmed,
                    "dropped": {
                        k.split("#", 1)[0]: v for k, v in c.outbox.dropped.items() if not k.startswith("\0")
                    },
                }
                for c in list(self._clients.values())
            ],
            "subscriptions": self.taps.topics(),
        }

    # -- standalone server --------------------------------------------------------------------
    def run_in_thread(self) -> str:
        """Start the gateway and its own HTTP server on a loop thread; returns the ws:// URL."""
        self.start()
        self._http = HttpServer(self.options.address, self.options.port, self.options.ssl_context())
        if self.options.static_dir is not None:
            self._http.static("/static", Path(self.options.static_dir))
        self.mount(self._http)
        started = threading.Event()
        errors: list[BaseException] = []

        def run() -> None:
            loop = self._loop = asyncio.new_event_loop()
            asyncio.set_event_loop(loop)
            try:
                assert self._http is not None
                loop.run_until_complete(self._http.start())
            except BaseException as exc:
                errors.append(exc)
                started.set()
                return
            started.set()
            try:
                loop.run_forever()
            finally:
                loop.run_until_complete(self._http.close())
                pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
                for task in pending:
                    task.cancel()
                loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))
                loop.close()

        self._thread = threading.Thread(target=run, name="gateway-loop", daemon=True)
        self._thread.start()
        started.wait(10.0)
        if errors:
            self.shutdown()
            raise errors[0]
        return self.url

    @property
    def url(self) -> str:
        assert self._http is not None
        return self._http.url.replace("http", "ws", 1)

    @property
    def port(self) -> int:
        assert self._http is not None
        return self._http.port

    def shutdown(self) -> None:
        """Close every client, stop polling; stops the loop only when the gateway runs its own."""
        self._stop.set()
        loop = self._loop
        if loop is not None and not loop.is_closed():
            try:
                for client in list(self._clients.values()):
                    loop.call_soon_threadsafe(client.ws.close, 1001, "server shutting down")
                if self._reporter is not None:
                    loop.call_soon_threadsafe(self._reporter.cancel)
                if self._thread is not None:
                    loop.call_soon_threadsafe(loop.stop)
            except RuntimeError:  # the loop closed meanwhile
                pass
        if self._thread is not None:
            self._thread.join(5.0)
        self.services.close()
        self.pool.shutdown(wait=False, cancel_futures=True)
        if self._own_node:
            self.node.shutdown("gateway shut down")
