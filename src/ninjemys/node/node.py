"""Node: one participant of a ROS graph (several may live in one process).

A Node owns its whole lifecycle:

* its names (caller id, namespace, remappings) and its servers (slave XML-RPC and TCPROS, both on
  the process's I/O loop), its registrations with the master;
* its ROS clock (:attr:`Node.clock`): wall time, or simulated time following ``/clock`` when
  ``/use_sim_time`` is set (``sim_time="auto"``), so two Nodes of one process may run on different
  time sources, each with its own ``rate``/``timer``/``sleep``;
* its ROS logging (:attr:`Node.log`): console, the log file under ``~/.ros/log`` and ``/rosout``,
  with ROS 1's level routing, and the ``~get_loggers``/``~set_logger_level`` services;
* its parameters, and every Publisher, Subscriber, ServiceServer and ServiceProxy made from it.

``shutdown`` tears all of that down and returns when nothing of the node is left running. The parts
(publications, subscriptions, services, registrar, slave API) reach the node only through
:class:`~ninjemys.node.context.NodeContext`.

``rostime.Time.now()`` reads the clock of the process's *default* node: the first Node created (or
the one created with ``default_clock=True``, which ``rospy.init_node`` does), wall time when there
is none. Libraries handed a Node should prefer :meth:`Node.now`.
"""

from __future__ import annotations

import logging
import socket
import threading
from collections.abc import Callable, Mapping

from ninjemys import interrupt, names, rostime
from ninjemys.errors import MasterError, NinjemysError, ShutdownError
from ninjemys.interrupt import wait_event
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import advertised_host, advertised_host_problem
from ninjemys.net.addresses import master_uri as env_master_uri
from ninjemys.net.xmlrpc_server import XmlRpcServer
from ninjemys.node import intraprocess, timers, transport
from ninjemys.node import runtime as _runtime
from ninjemys.node.clock import CLOCK_TOPIC, USE_SIM_TIME, Clock
from ninjemys.node.log import INFO, NodeLog
from ninjemys.node.params import ParamAccess
from ninjemys.node.registration import Registrar
from ninjemys.node.services import ServiceProxy, ServiceServer
from ninjemys.node.slave import SlaveApi
from ninjemys.node.subscriber import Subscriber, Subscription
from ninjemys.node.topics import PubConnection, Publication, Publisher

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_log = logging.getLogger(__name__)


class Node(ParamAccess):
    """A ROS node: ``Node("talker")``, then ``publisher``, ``subscriber``, ``service``, ``service_proxy``."""

    def __init__(
        self,
        name: str,
        namespace: str = "/",
        anonymous: bool = False,
        remappings: Mapping[str, str] | None = None,
        master_uri: str | None = None,
        params: Mapping[str, Any] | None = None,
        *,
        sim_time: bool | str = "auto",
        clock: Clock | None = None,
        rosout: bool = True,
        logger_services: bool = True,
        log_level: int = INFO,
        log_file: str | None = None,
        default_clock: bool | None = None,
        strict_names: bool = True,
    ) -> None:
        """Register node ``name`` with the master and start its servers, clock and logging.

        Args:
            name: base name (``talker``) or global name; ``anonymous`` appends ``_<pid>_<ms>``.
            namespace, remappings, master_uri: as ``__ns:=``, ``from:=to`` and ``__master:=``.
            params: private parameters (``_rate:=10``) set at start.
            sim_time: ``"auto"`` follows ``/clock`` when ``/use_sim_time`` is true at start (ROS 1);
                True always follows ``/clock``; False is wall time.
            clock: a :class:`~ninjemys.node.clock.Clock` to drive instead of a new one. A simulated
                clock (``ninjemys.testing.FakeClock``) is used as it is, driven by its owner; a wall
                clock is switched to ``/clock`` when ``sim_time`` says so (rospy hands over the
                clock its pre-``init_node`` Rates and Timers already wait on).
            rosout: publish every enabled log message on ``/rosout`` (latched rosgraph_msgs/Log).
            logger_services: provide ``~get_loggers`` and ``~set_logger_level`` (roscpp/srv).
            log_level: console and /rosout threshold (``ninjemys.node.log.DEBUG`` ... ``FATAL``).
            log_file: the log file's path (``__log:=``), else ``<log dir>/<node>-<pid>.log``.
            default_clock: make this node's clock the one ``rostime.Time.now()`` reads. None
                (default) takes the place when no live node holds it; True takes it anyway; False never.
            strict_names: refuse names that ROS 1 calls illegal (``a b``, ``1x``, ``a-b``) for the
                node and for what it resolves. False is rospy's leniency: such names are used as
                given (rospy only warns) and the master decides what it registers.
        """
        if sim_time not in ("auto", True, False):
            raise ValueError(f"Node: sim_time must be 'auto', True or False, not {sim_time!r}")
        if not name or "~" in name or (strict_names and not names.is_legal_name(name.lstrip("/"))):
            raise names.NameError_(f"node name [{name}] is not a legal ROS name")
        self.strict_names = strict_names
        if anonymous:
            name = names.rospy_anonymous_name(name)
        ns = names.make_global_ns(namespace or "/")
        self.name: str = names.canonicalize_name(name if name.startswith("/") else ns + name)
        self.namespace: str = names.namespace(self.name)
        self.remappings: dict[str, str] = names.resolve_remappings(remappings or {}, self.name)
        self.master_uri: str = master_uri or env_master_uri()
        self.master = MasterClient(self.master_uri, self.name)
        self._publications: dict[str, Publication] = {}
        self._subscriptions: dict[str, Subscription] = {}
        self._services: dict[str, ServiceServer] = {}
        self._proxies: list[ServiceProxy] = []
        self._param_callbacks: dict[str, list[Callable[[str, Any], None]]] = {}
        self._shutdown_hooks: list[Callable[[], Any]] = []
        self._timers: list[timers.Timer] = []
        self._lock = threading.RLock()
        self._shutdown_event = interrupt.Event()  # spin() waits on it with no periodic wake-up
        self._shutdown_done = threading.Event()
        self.shutdown_reason = ""
        self.tcpros_host = advertised_host()
        self.runtime = _runtime.acquire()
        try:
            self._tcpros = transport.TcprosServer(self._on_topic_connection, self._on_service_connection)
            self.tcpros_port = self._tcpros.port
            self.unix_address: str | None = self._tcpros.unix_address
            self._slave = XmlRpcServer(SlaveApi(self), "0.0.0.0", 0, advertise=self.tcpros_host)
            self.runtime.run(self._start_servers(), timeout=10.0)
        except BaseException:
            _runtime.release()
            raise
        self.uri: str = self._slave.uri
        intraprocess.register_node(self.uri, self)  # in-process subscribers find our publications
        self.registrar = Registrar(self)
        self.registrar.start()
        # the clock and the log exist before anything below can fail, so shutdown always finds them
        self.clock: Clock = clock if clock is not None else Clock()
        self.log: NodeLog = NodeLog(self.name, level=log_level, log_file=log_file)
        # a name peers cannot resolve: say so once, now, not as each peer's failed connection later
        # (the lookup may wait on DNS: the loop's helper thread does it)
        self.runtime.loop.call_soon_threadsafe(self._check_advertised_host)
        try:
            for key, value in (params or {}).items():
                try:
                    self.set_param("~" + key.lstrip("~"), value)
                except MasterError as exc:
                    _log.warning("%s: could not set private parameter %s: %s", self.name, key, exc)
            self._start_clock(sim_time, clock is not None and clock.is_sim)
            if rosout:
                self._start_rosout()
            if logger_services:
                self._start_logger_services()
        except BaseException:
            self.shutdown("start-up failed")
            raise
        if default_clock or (default_clock is None and rostime.default_clock_owner() is None):
            rostime.claim_default_clock(self, None if self.clock.is_wallclock else self.clock.now_pair)

    def _start_clock(self, sim_time: bool | str, driven: bool) -> None:
        """Follow ``/clock`` when simulated time is asked for (or, for "auto", when ``/use_sim_time``
        is true: read once, at start, as in ROS 1). A clock already simulated is driven by its owner."""
        if driven:
            self.log.set_ros_time(self.clock.now)
            return
        if sim_time == "auto":
            try:
                sim = bool(self.get_param(USE_SIM_TIME, False))
            except NinjemysError:
                sim = False  # an unreachable parameter server means wall time, as in rospy
        else:
            sim = bool(sim_time)
        if not sim:
            return
        from ninjemys.idl.loader import get_message_class

        self.clock.switch_to_sim()
        self.subscriber(
            CLOCK_TOPIC, get_message_class("rosgraph_msgs/Clock"), self.clock.on_clock_message, queue_size=1
        )
        self.log.set_ros_time(self.clock.now)

    def _start_rosout(self) -> None:
        from ninjemys.idl.loader import get_message_class

        log_class = get_message_class("rosgraph_msgs/Log")
        pub = self.publisher("/rosout", log_class, queue_size=100, latch=True)
        self.log.attach_rosout(pub, log_class, self._publication_names)

    def _publication_names(self) -> list[str]:
        return list(self._publications)

    def _start_logger_services(self) -> None:
        from ninjemys.idl.loader import get_message_class, get_service_class

        get_loggers: Any = get_service_class("roscpp/GetLoggers")
        set_level: Any = get_service_class("roscpp/SetLoggerLevel")
        logger_class = get_message_class("roscpp/Logger")
        log = self.log
        self.service(
            "~get_loggers", get_loggers, log.get_loggers_handler(get_loggers._response_class, logger_class)
        )
        self.service("~set_logger_level", set_level, log.set_logger_level_handler(set_level._response_class))

    async def _start_servers(self) -> None:
        self._tcpros.start()
        await self._slave.start()

    def __repr__(self) -> str:
        return f"Node({self.name!r}, uri={getattr(self, 'uri', '?')!r})"

    # -- names -----------------------------------------------------------------------------------

    def resolve_name(self, name: str) -> str:
        """Resolve ``name`` (relative, ``~private`` or global) in this node's namespace, then remap it."""
        if not isinstance(name, str) or (self.strict_names and not names.is_legal_name(name)):
            raise names.NameError_(f"[{name}] is not a legal ROS graph name")
        return names.resolve_name(name, self.name, self.remappings)

    @property
    def is_shutdown(self) -> bool:
        return self._shutdown_event.is_set()

    def _check_alive(self) -> None:
        if self._shutdown_event.is_set():
            raise ShutdownError(f"node {self.name} is shut down ({self.shutdown_reason})")

    def _check_advertised_host(self) -> None:
        """On the loop: look the advertised host up on a helper thread; log why peers cannot reach us."""

        def check() -> None:
            problem = advertised_host_problem(self.tcpros_host)
            if problem is not None:
                self.log.error("%s", problem)

        self.runtime.loop.run_in_thread(check)

    # -- topics ----------------------------------------------------------------------------------

    def publisher(
        self,
        topic: str,
        msg_class: Any,
        queue_size: int | None = 10,
        latch: bool = False,
        tcp_nodelay: bool = True,
        headers: Mapping[str, str] | None = None,
        intraprocess: bool = False,
    ) -> Publisher:
        """Advertise ``topic``. ``tcp_nodelay`` is accepted for API symmetry: a publisher sets
        TCP_NODELAY on every subscriber's socket (it batches bursts itself; docs/node.md).
        ``intraprocess=True`` promises never to change a message after publishing it: subscriber
        handles of this process made with ``intraprocess=True`` then get the object itself, not
        serialized (docs/node.md, in-process delivery)."""
        self._check_alive()
        resolved = self.resolve_name(topic)
        with self._lock:
            pub = self._publications.get(resolved)
            new = pub is None
            if pub is None:
                pub = Publication(self, resolved, msg_class)
                self._publications[resolved] = pub
            elif pub.md5sum != msg_class._md5sum:
                raise NinjemysError(
                    f"topic {resolved} is already published by {self.name} as {pub.type_name}, not {msg_class._type}"
                )
            handle = Publisher(pub, queue_size, latch, headers, intraprocess)
            pub.handles.append(handle)
            # the master hears of this topic's changes in the order they were made here
            place = self.registrar.turns.take("pub", resolved) if new else None
        if place is not None:
            self.registrar.add_publisher(resolved, pub.type_name, place)
        return handle

    def subscriber(
        self,
        topic: str,
        msg_class: Any,
        callback: Callable[..., Any] | None,
        callback_args: Any = None,
        queue_size: int | None = None,
        raw: bool = False,
        tcp_nodelay: bool = True,
        coalesce: float = 0.0,
        share_thread: Subscriber | None = None,
        lazy: float = 0.0,
        batch: bool = False,
        intraprocess: bool = False,
        direct: bool = False,
    ) -> Subscriber:
        """Subscribe to ``topic``; ``callback(msg[, callback_args])`` runs on this subscriber's own thread.

        ``raw=True`` (or ``msg_class=None``) delivers :class:`~ninjemys.node.subscriber.RawMessage`
        (serialized bytes plus the publisher's connection header) without deserializing.
        ``coalesce=s`` lets a message wait up to about ``s`` seconds so that one wake-up of the
        subscriber's thread takes all that arrived meanwhile: on a VM a wake-up costs more CPU than
        a small message (``rostopic echo`` and ``bw`` use it; not ``hz``, whose statistics need each
        message's own arrival time, and TCP merges segments that wait, with their kernel times).
        ``share_thread=handle`` delivers on ``handle``'s thread instead of a new one: one wake-up then
        serves messages of several topics that arrive together (message_filters' synchronizers), and
        the callbacks of those subscriptions run one after another, as under roscpp's single spinner.
        ``lazy=s`` is for data read only when asked for (a tf listener's ``/tf``): the thread reads
        what the kernel holds every ``s`` seconds at most (sooner when that much would fill a socket's
        receive buffer) instead of waking per message; ``handle.pull()`` reads and delivers on the
        caller's thread before the data is used, and ``handle.set_eager(True)`` restores a wake-up per
        message while something waits for the data (with ``share_thread``, the host's setting rules).
        ``batch=True`` calls back with a list: the messages read in one go, in order (a lazy reader's
        round or pull can hold many; one call saves the per-message call overhead).
        ``intraprocess=True`` connects to publishers of this same process without a socket or
        serialization (the transport ``INTRAPROCESS``) and promises never to change a received
        message: from a publisher made with ``intraprocess=True`` too, the callback gets the
        published object itself, shared with that publisher and every such subscriber; otherwise its
        own copy (docs/node.md, in-process delivery).
        ``direct=True`` (with ``intraprocess=True``) lets an in-process publisher's thread run the
        callback itself, inside ``publish()``, when this handle is idle (nothing queued, no callback
        running), as a nodelet's publish does: no thread wake-up, so a round trip costs a few
        microseconds; a callback that takes long then delays that ``publish()``. Otherwise (busy, or
        from another process) the message is queued for the handle's thread as usual.
        """
        self._check_alive()
        if direct and not intraprocess:
            raise NinjemysError(f"subscriber of {topic}: direct=True needs intraprocess=True")
        if direct and (lazy or share_thread is not None):
            raise NinjemysError(
                f"subscriber of {topic}: direct=True cannot be combined with lazy or share_thread"
            )
        resolved = self.resolve_name(topic)
        with self._lock:
            sub = self._subscriptions.get(resolved)
            new = sub is None
            if sub is None:
                sub = Subscription(self, resolved, msg_class, tcp_nodelay)
                self._subscriptions[resolved] = sub
            handle = Subscriber(
                sub, callback, callback_args, queue_size, raw, coalesce, share_thread, lazy, batch,
                intraprocess, direct,
            )  # fmt: skip
            sub.handles.append(handle)
            place = self.registrar.turns.take("sub", resolved) if new else None
        if place is not None:
            updates = sub.updates  # 0: read before the master can notify us of this topic
            publishers = self.registrar.add_subscriber(resolved, sub.type_name, place)
            if publishers is not None:
                self.publisher_update(resolved, publishers, updates)
        else:
            self.runtime.call_soon(self._replay_latched, sub, handle)
        return handle

    @staticmethod
    def _replay_latched(sub: Subscription, handle: Subscriber) -> None:
        for frame, header in sub.latched_frames():
            handle.enqueue([frame], header)

    # -- NodeContext: calls back from the node's parts ------------------------------------------------

    def publisher_update(self, topic: str, publishers: list[str], updates: int | None = None) -> None:
        """Connect to the current publishers of ``topic`` (from the master: slave API, re-registration).
        Just after a master restart the list may be short of publishers that have not re-registered
        yet: live connections are then kept (registration.py, ``settling``). ``updates``: the list is
        the master's answer to a registerSubscriber sent when :meth:`publisher_updates` said that; it
        is dropped if a publisherUpdate (newer) was applied since (``Subscription.registered``)."""
        sub = self._subscriptions.get(topic)
        if sub is None:
            return
        if updates is None:
            self.runtime.call_soon(sub.update_publishers, publishers, self.registrar.settling())
        else:
            self.runtime.call_soon(sub.registered, publishers, updates, self.registrar.settling())

    def publisher_updates(self, topic: str) -> int:
        """How many publisher lists the subscription of ``topic`` has applied (0 if none)."""
        sub = self._subscriptions.get(topic)
        return 0 if sub is None else sub.updates

    def release_publisher(self, handle: Publisher) -> None:
        """Forget an unregistered Publisher handle; the topic's last one unregisters the topic."""
        with self._lock:
            pub = self._publications.get(handle.resolved_name)
            if pub is None or handle not in pub.handles:
                return
            pub.handles.remove(handle)
            if pub.handles:
                return
            del self._publications[pub.topic]
            place = self.registrar.turns.take("pub", pub.topic)
        self.registrar.remove_publisher(pub.topic, place=place)
        pub.close()

    def release_subscriber(self, handle: Subscriber) -> None:
        """Forget an unregistered Subscriber handle; the topic's last one unregisters the topic."""
        with self._lock:
            sub = self._subscriptions.get(handle.resolved_name)
            if sub is None or handle not in sub.handles:
                return
            sub.handles.remove(handle)
            if sub.handles:
                return
            del self._subscriptions[sub.topic]
            place = self.registrar.turns.take("sub", sub.topic)
        self.registrar.remove_subscriber(sub.topic, place=place)
        self.runtime.call_soon(sub.close)

    def connection_closed(self, conn: PubConnection) -> None:
        """A subscriber's connection to one of our publications ended (on the I/O loop)."""
        pub = self._publications.get(conn.topic)
        if pub is not None:
            pub.remove_connection(conn)

    async def _on_topic_connection(self, sock: socket.socket, header: Mapping[str, str]) -> None:
        pub = self._publications.get(header["topic"])
        if pub is None:
            _log.info("%s: refused a subscriber of %s: not published here", self.name, header["topic"])
            await transport.send_error_header(sock, f"node {self.name} does not publish {header['topic']}")
            transport.close_quietly(sock)
            return
        await pub.accept(sock, header)

    def publishes(self, topic: str) -> bool:
        """True when this node publishes ``topic``."""
        return topic in self._publications

    def get_publications(self) -> list[list[str]]:
        return [[t, p.type_name] for t, p in list(self._publications.items())]

    def get_subscriptions(self) -> list[list[str]]:
        return [[t, s.type_name] for t, s in list(self._subscriptions.items())]

    # -- services --------------------------------------------------------------------------------

    def service(self, name: str, service_class: Any, handler: Callable[[Any], Any]) -> ServiceServer:
        """Provide service ``name``; ``handler(request)`` runs on the calling client's connection thread."""
        self._check_alive()
        resolved = self.resolve_name(name)
        with self._lock:
            if resolved in self._services:
                raise NinjemysError(f"service [{resolved}] is already provided by {self.name}")
            server = ServiceServer(self, resolved, service_class, handler)
            self._services[resolved] = server
            place = self.registrar.turns.take("srv", resolved)
        self.registrar.add_service(resolved, f"rosrpc://{self.tcpros_host}:{self.tcpros_port}", place)
        return server

    def service_proxy(
        self,
        name: str,
        service_class: Any,
        persistent: bool = False,
        headers: Mapping[str, str] | None = None,
    ) -> ServiceProxy:
        """A callable client of service ``name`` (``persistent`` keeps one connection open)."""
        self._check_alive()
        proxy = ServiceProxy(self, self.resolve_name(name), service_class, persistent, headers)
        with self._lock:
            self._proxies.append(proxy)
        return proxy

    def wait_for_service(self, name: str, timeout: float | None = None) -> None:
        """Block until service ``name`` is available (TimeoutError_ after ``timeout`` seconds)."""
        probe = ServiceProxy(self, self.resolve_name(name), _ProbeService)
        probe.wait_for_service(timeout)

    def release_service(self, server: ServiceServer) -> None:
        """Forget a service server its owner shut down, and unregister it."""
        with self._lock:
            if self._services.get(server.name) is not server:
                return
            del self._services[server.name]
            place = self.registrar.turns.take("srv", server.name)
        self.registrar.remove_service(server.name, place=place)

    async def _on_service_connection(self, sock: socket.socket, header: Mapping[str, str]) -> None:
        server = self._services.get(header["service"])
        if server is None:
            _log.info("%s: refused a client of %s: not provided here", self.name, header["service"])
            await transport.send_error_header(sock, f"node {self.name} does not provide {header['service']}")
            transport.close_quietly(sock)
            return
        await server.accept(sock, header)

    # -- parameters (get/set/has/delete/search/get_param_names: ParamAccess) ----------------------

    def subscribe_param(self, key: str, callback: Callable[[str, Any], None]) -> Any:
        """Call ``callback(key, value)`` (on a helper thread) whenever ``key`` changes; returns the value now."""
        resolved = self.resolve_name(key)
        canonical = resolved.rstrip("/") + "/"
        with self._lock:
            self._param_callbacks.setdefault(canonical, []).append(callback)
        return self.registrar.add_param_subscription(resolved)

    def param_update(self, key: str, value: Any) -> bool:
        """Run the callbacks of a subscribed parameter that changed; False when none subscribes ``key``."""
        canonical = key.rstrip("/") + "/"
        callbacks = [
            (k, cb)
            for k, cbs in list(self._param_callbacks.items())
            for cb in cbs
            if canonical.startswith(k) or k.startswith(canonical)
        ]
        if not callbacks:
            return False

        def run() -> None:
            for _, cb in callbacks:
                try:
                    cb(key.rstrip("/"), value)
                except Exception:
                    _log.exception("parameter callback for %s raised", key)

        self.runtime.start_thread(run, "param-update")
        return True

    # -- introspection (slave API) ---------------------------------------------------------------

    def bus_stats(self) -> list[Any]:
        pubs = [
            [t, sum(c.bytes_sent for c in p.connections) + p.bytes_sent_closed,
             [[c.id, c.bytes_sent, c.num_sent, not c.closed] for c in p.all_connections()]]
            for t, p in list(self._publications.items())
        ]  # fmt: skip
        subs = [
            [t, [[c.id, c.bytes_recv, c.num_recv, -1, not c.closed] for c in list(s.connections.values())]]
            for t, s in list(self._subscriptions.items())
        ]
        return [pubs, subs, [0, 0, 0]]

    def bus_info(self) -> list[Any]:
        info: list[Any] = []
        for topic, pub in list(self._publications.items()):
            for c in pub.all_connections():
                info.append(
                    [c.id, c.subscriber, "o", c.transport, topic, not c.closed,
                     f"{c.transport} connection to [{c.subscriber}]"]
                )  # fmt: skip
        for topic, sub in list(self._subscriptions.items()):
            for s in list(sub.connections.values()):
                info.append(
                    [s.id, s.uri, "i", s.transport, topic, not s.closed,
                     f"{s.transport} connection from [{s.publisher}]"]
                )  # fmt: skip
        return info

    # -- time ------------------------------------------------------------------------------------

    def now(self) -> rostime.Time:
        """This node's ROS time as a Time (simulated time under ``/use_sim_time``: 0 until the first /clock)."""
        secs, nsecs = self.clock.now_pair()
        return rostime.Time._raw(secs, nsecs)

    def get_time(self) -> float:
        """This node's ROS time in float seconds."""
        return self.clock.now()

    def sleep(self, duration: Any) -> None:
        """Sleep ``duration`` (seconds or a Duration) of this node's ROS time; ShutdownError on shutdown."""
        timers.sleep(self.clock, duration)

    def rate(self, hz: float, reset: bool = True) -> timers.Rate:
        """A :class:`~ninjemys.node.timers.Rate` on this node's clock (``rate.sleep()`` once per loop)."""
        return timers.Rate(hz, self.clock, reset=reset)

    def timer(
        self, period: Any, callback: Callable[[timers.TimerEvent], Any], oneshot: bool = False
    ) -> timers.Timer:
        """Call ``callback(TimerEvent)`` every ``period`` of this node's ROS time, on its own thread.

        Event times are ``rostime.Time``; an exception in the callback is logged to the node's log
        and the timer carries on. The timer stops when the node shuts down.
        """
        self._check_alive()
        timer = timers.Timer(
            self.clock,
            period,
            callback,
            oneshot=oneshot,
            make_time=rostime.Time.from_sec,
            on_error=self._timer_failed,
            name=f"timer:{self.name}",
        )
        with self._lock:
            self._timers = [t for t in self._timers if t.is_alive()]
            self._timers.append(timer)
        return timer

    def _timer_failed(self, exc: BaseException) -> None:
        self.log.error("Timer callback raised %s: %s", type(exc).__name__, exc)

    # -- lifecycle -------------------------------------------------------------------------------

    def on_shutdown(self, fn: Callable[[], Any]) -> None:
        """Run ``fn()`` when the node shuts down (immediately if it already has)."""
        if self._shutdown_event.is_set():
            fn()
            return
        self._shutdown_hooks.append(fn)

    def wait_for_shutdown(self, timeout: float | None = None) -> bool:
        """Block until the node is shut down (or ``timeout`` passes); True if it is."""
        return wait_event(self._shutdown_event, timeout)

    def spin(self) -> None:
        """Block until shutdown."""
        wait_event(self._shutdown_event)

    def shutdown(self, reason: str = "") -> None:
        """Unregister everything, close every connection and stop every thread of this node."""
        with self._lock:
            if self._shutdown_event.is_set():
                first = False
            else:
                first = True
                self.shutdown_reason = reason
                self._shutdown_event.set()
        if not first:
            self._shutdown_done.wait(10.0)
            return
        try:
            self._teardown()
        finally:
            self._shutdown_done.set()

    def _teardown(self) -> None:
        for hook in list(self._shutdown_hooks):
            try:
                hook()
            except Exception:
                _log.exception("shutdown hook %r raised", hook)
        # wake every sleeper, Rate and Timer of this node for good; stop sending to /rosout
        self.clock.shutdown()
        self.log.detach()
        rostime.release_default_clock(self)
        intraprocess.unregister_node(self.uri, self)
        with self._lock:
            node_timers, self._timers = self._timers, []
        self.registrar.stop()
        quick = MasterClient(self.master_uri, self.name, timeout=1.0)
        turns = self.registrar.turns
        with self._lock:
            pubs = list(self._publications.values())
            subs = list(self._subscriptions.values())
            srvs = list(self._services.values())
            proxies = list(self._proxies)
            self._publications.clear()
            self._subscriptions.clear()
            self._services.clear()
            places = (
                [turns.take("sub", sub.topic) for sub in subs],
                [turns.take("pub", pub.topic) for pub in pubs],
                [turns.take("srv", srv.name) for srv in srvs],
            )
        try:
            for sub, place in zip(subs, places[0], strict=True):
                self.registrar.remove_subscriber(sub.topic, quick, place)
            for pub, place in zip(pubs, places[1], strict=True):
                self.registrar.remove_publisher(pub.topic, quick, place)
            for srv, place in zip(srvs, places[2], strict=True):
                self.registrar.remove_service(srv.name, quick, place)
        finally:
            quick.close()
        for srv in srvs:
            srv.closed = True
        for proxy in proxies:
            proxy.close()
        for pub in pubs:
            pub.close()
        handles = [h for sub in subs for h in sub.handles]
        for handle in handles:
            handle._closed = True
            handle._wakeup()
        try:
            self.runtime.run(self._close_servers(subs), timeout=5.0)
        except NinjemysError as exc:
            _log.debug("closing servers: %s", exc)
        for handle in handles:
            if handle._thread is not threading.current_thread():
                handle._thread.join(2.0)
        for timer in node_timers:
            timer.join(2.0)
        self.master.close()
        _runtime.release()

    async def _close_servers(self, subs: list[Subscription]) -> None:
        for sub in subs:
            sub.close()
        self._tcpros.close()
        self._slave.close()

    def __enter__(self) -> Node:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown("context exit")


class _ProbeService:
    """A stand-in service class for probing availability by name alone (md5 ``*``)."""

    _type = "*"
    _md5sum = "*"
    _request_class = None
    _response_class = None
