"""Node: one participant of a ROS graph (several may live in one process).

A Node owns its names (caller id, namespace, remappings), its servers (slave XML-RPC and TCPROS,
both on the process's I/O loop), its registrations with the master, and every Publisher,
Subscriber, ServiceServer and ServiceProxy made from it. ``shutdown`` tears all of that down and
returns when nothing of the node is left running.
"""

from __future__ import annotations

import logging
import socket
import threading
from collections.abc import Callable, Mapping

from ninjemys import names
from ninjemys.errors import MasterError, NinjemysError, ParameterError, ShutdownError
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import advertised_host
from ninjemys.net.addresses import master_uri as env_master_uri
from ninjemys.net.xmlrpc_server import XmlRpcServer
from ninjemys.node import runtime as _runtime
from ninjemys.node import transport
from ninjemys.node.registration import Registrar
from ninjemys.node.services import ServiceProxy, ServiceServer
from ninjemys.node.slave import SlaveApi
from ninjemys.node.subscriber import Subscriber, Subscription
from ninjemys.node.topics import Publication, Publisher

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_log = logging.getLogger(__name__)
_UNSET = object()


class Node:
    """A ROS node: ``Node("talker")``, then ``publisher``, ``subscriber``, ``service``, ``service_proxy``."""

    def __init__(
        self,
        name: str,
        namespace: str = "/",
        anonymous: bool = False,
        remappings: Mapping[str, str] | None = None,
        master_uri: str | None = None,
        params: Mapping[str, Any] | None = None,
    ) -> None:
        if not name or not names.is_legal_name(name.lstrip("/")) or "~" in name:
            raise names.NameError_(f"node name [{name}] is not a legal ROS name")
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
        self._lock = threading.RLock()
        self._shutdown_event = threading.Event()
        self._shutdown_done = threading.Event()
        self.shutdown_reason = ""
        self.tcpros_host = advertised_host()
        self.runtime = _runtime.acquire()
        try:
            self._tcpros = transport.TcprosServer(self._on_topic_connection, self._on_service_connection)
            self.tcpros_port = self._tcpros.port
            self._slave = XmlRpcServer(SlaveApi(self), "0.0.0.0", 0, advertise=self.tcpros_host)
            self.runtime.run(self._start_servers(), timeout=10.0)
        except BaseException:
            _runtime.release()
            raise
        self.uri: str = self._slave.uri
        self.registrar = Registrar(self)
        self.registrar.start()
        for key, value in (params or {}).items():
            try:
                self.set_param("~" + key.lstrip("~"), value)
            except MasterError as exc:
                _log.warning("%s: could not set private parameter %s: %s", self.name, key, exc)

    async def _start_servers(self) -> None:
        self._tcpros.start()
        await self._slave.start()

    def __repr__(self) -> str:
        return f"Node({self.name!r}, uri={getattr(self, 'uri', '?')!r})"

    # -- names -----------------------------------------------------------------------------------

    def resolve_name(self, name: str) -> str:
        """Resolve ``name`` (relative, ``~private`` or global) in this node's namespace, then remap it."""
        if not names.is_legal_name(name):
            raise names.NameError_(f"[{name}] is not a legal ROS graph name")
        return names.resolve_name(name, self.name, self.remappings)

    @property
    def is_shutdown(self) -> bool:
        return self._shutdown_event.is_set()

    def _check_alive(self) -> None:
        if self._shutdown_event.is_set():
            raise ShutdownError(f"node {self.name} is shut down ({self.shutdown_reason})")

    # -- topics ----------------------------------------------------------------------------------

    def publisher(
        self,
        topic: str,
        msg_class: Any,
        queue_size: int | None = 10,
        latch: bool = False,
        tcp_nodelay: bool = True,
        headers: Mapping[str, str] | None = None,
    ) -> Publisher:
        """Advertise ``topic``. ``tcp_nodelay`` is what our subscribers ask for; a publisher honours
        each subscriber's own request, so the flag is accepted for API symmetry."""
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
            handle = Publisher(pub, queue_size, latch, headers)
            pub.handles.append(handle)
        if new:
            self.registrar.add_publisher(resolved, pub.type_name)
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
    ) -> Subscriber:
        """Subscribe to ``topic``; ``callback(msg[, callback_args])`` runs on this subscriber's own thread.

        ``raw=True`` (or ``msg_class=None``) delivers :class:`~ninjemys.node.subscriber.RawMessage`
        (serialized bytes plus the publisher's connection header) without deserializing.
        ``coalesce=s`` lets a message wait up to about ``s`` seconds so that one wake-up of the
        subscriber's thread takes all that arrived meanwhile: on a VM a wake-up costs more CPU than
        a small message (``rostopic echo`` and ``bw`` use it; not ``hz``, whose statistics need each
        message's own arrival time, and TCP merges segments that wait, with their kernel times).
        """
        self._check_alive()
        resolved = self.resolve_name(topic)
        with self._lock:
            sub = self._subscriptions.get(resolved)
            new = sub is None
            if sub is None:
                sub = Subscription(self, resolved, msg_class, tcp_nodelay)
                self._subscriptions[resolved] = sub
            handle = Subscriber(sub, callback, callback_args, queue_size, raw, coalesce)
            sub.handles.append(handle)
        if new:
            publishers = self.registrar.add_subscriber(resolved, sub.type_name)
            if publishers is not None:
                self._publisher_update(resolved, publishers)
        else:
            self.runtime.call_soon(self._replay_latched, sub, handle)
        return handle

    @staticmethod
    def _replay_latched(sub: Subscription, handle: Subscriber) -> None:
        for frame, header in sub.latched_frames():
            handle.enqueue([frame], header)

    def _publisher_update(self, topic: str, publishers: list[str]) -> None:
        sub = self._subscriptions.get(topic)
        if sub is not None:
            self.runtime.call_soon(sub.update_publishers, publishers)

    def _drop_publisher(self, handle: Publisher) -> None:
        with self._lock:
            pub = self._publications.get(handle.resolved_name)
            if pub is None or handle not in pub.handles:
                return
            pub.handles.remove(handle)
            if pub.handles:
                return
            del self._publications[pub.topic]
        self.registrar.remove_publisher(pub.topic)
        pub.close()

    def _drop_subscriber(self, handle: Subscriber) -> None:
        with self._lock:
            sub = self._subscriptions.get(handle.resolved_name)
            if sub is None or handle not in sub.handles:
                return
            sub.handles.remove(handle)
            if sub.handles:
                return
            del self._subscriptions[sub.topic]
        self.registrar.remove_subscriber(sub.topic)
        self.runtime.call_soon(sub.close)

    def _topic_connection_closed(self, conn: Any) -> None:
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
        self.registrar.add_service(resolved, f"rosrpc://{self.tcpros_host}:{self.tcpros_port}")
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

    def _drop_service(self, server: ServiceServer) -> None:
        with self._lock:
            if self._services.get(server.name) is not server:
                return
            del self._services[server.name]
        self.registrar.remove_service(server.name)

    async def _on_service_connection(self, sock: socket.socket, header: Mapping[str, str]) -> None:
        server = self._services.get(header["service"])
        if server is None:
            _log.info("%s: refused a client of %s: not provided here", self.name, header["service"])
            await transport.send_error_header(sock, f"node {self.name} does not provide {header['service']}")
            transport.close_quietly(sock)
            return
        await server.accept(sock, header)

    # -- parameters ------------------------------------------------------------------------------

    def get_param(self, key: str, default: Any = _UNSET) -> Any:
        """The value of ``key`` (resolved like a topic name); ``default`` if unset, else ParameterError."""
        resolved = self.resolve_name(key)
        try:
            return self.master.get_param(resolved)
        except MasterError as exc:
            if getattr(exc, "code", None) not in (-1, 0):
                raise  # unreachable master, protocol trouble: not "unset"
            if default is not _UNSET:
                return default
            raise ParameterError(f"parameter [{resolved}] is not set") from None

    def set_param(self, key: str, value: Any) -> None:
        self.master.set_param(self.resolve_name(key), value)

    def has_param(self, key: str) -> bool:
        return bool(self.master.has_param(self.resolve_name(key)))

    def delete_param(self, key: str) -> None:
        resolved = self.resolve_name(key)
        try:
            self.master.delete_param(resolved)
        except MasterError as exc:
            if getattr(exc, "code", None) in (-1, 0):
                raise ParameterError(f"parameter [{resolved}] is not set") from None
            raise

    def search_param(self, key: str) -> str | None:
        try:
            return self.master.search_param(key)
        except MasterError as exc:
            if getattr(exc, "code", None) in (-1, 0):
                return None
            raise

    def get_param_names(self) -> list[str]:
        return list(self.master.get_param_names())

    def subscribe_param(self, key: str, callback: Callable[[str, Any], None]) -> Any:
        """Call ``callback(key, value)`` (on a helper thread) whenever ``key`` changes; returns the value now."""
        resolved = self.resolve_name(key)
        canonical = resolved.rstrip("/") + "/"
        with self._lock:
            self._param_callbacks.setdefault(canonical, []).append(callback)
        return self.registrar.add_param_subscription(resolved)

    def _param_update(self, key: str, value: Any) -> bool:
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
             [[c.id, c.bytes_sent, c.num_sent, not c.closed] for c in p.connections]]
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
            for c in pub.connections:
                info.append(
                    [
                        c.id,
                        c.subscriber,
                        "o",
                        "TCPROS",
                        topic,
                        not c.closed,
                        f"TCPROS connection to [{c.subscriber}]",
                    ]
                )
        for topic, sub in list(self._subscriptions.items()):
            for c in list(sub.connections.values()):
                info.append(
                    [
                        c.id,
                        c.uri,
                        "i",
                        "TCPROS",
                        topic,
                        not c.closed,
                        f"TCPROS connection from [{c.publisher}]",
                    ]
                )
        return info

    # -- lifecycle -------------------------------------------------------------------------------

    def on_shutdown(self, fn: Callable[[], Any]) -> None:
        """Run ``fn()`` when the node shuts down (immediately if it already has)."""
        if self._shutdown_event.is_set():
            fn()
            return
        self._shutdown_hooks.append(fn)

    def wait_for_shutdown(self, timeout: float | None = None) -> bool:
        """Block until the node is shut down (or ``timeout`` passes); True if it is."""
        return self._shutdown_event.wait(timeout)

    def spin(self) -> None:
        """Block until shutdown."""
        self._shutdown_event.wait()

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
        self.registrar.stop()
        quick = MasterClient(self.master_uri, self.name, timeout=1.0)
        with self._lock:
            pubs = list(self._publications.values())
            subs = list(self._subscriptions.values())
            srvs = list(self._services.values())
            proxies = list(self._proxies)
            self._publications.clear()
            self._subscriptions.clear()
            self._services.clear()
        try:
            for sub in subs:
                self.registrar.remove_subscriber(sub.topic, quick)
            for pub in pubs:
                self.registrar.remove_publisher(pub.topic, quick)
            for srv in srvs:
                self.registrar.remove_service(srv.name, quick)
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
