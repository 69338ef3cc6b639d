"""Synchronous client of the ROS 1 master and parameter server (any master: ours or rosmaster).

Each method performs one XML-RPC call and returns the *value* of ROS 1's ``[code, status, value]``
triple, or raises :class:`~ninjemys.errors.MasterError` (code -1 or 0; the exception carries
``code``, ``status`` and ``method``) or :class:`~ninjemys.errors.MasterUnreachable` (nothing answers).
One keep-alive HTTP connection is reused across calls (guarded by a lock, so a client may be shared
between threads); it is re-opened once if the master closed it in between.
"""

from __future__ import annotations

import socket
import threading

from ninjemys.errors import MasterError, MasterUnreachable, ProtocolError
from ninjemys.net import auth
from ninjemys.net.addresses import lookup_host, split_uri
from ninjemys.net.addresses import master_uri as default_master_uri
from ninjemys.wire import xmlrpc as wire

TYPE_CHECKING = False  # importing typing costs ~7 ms of every tool's and node's start-up
if TYPE_CHECKING:
    from typing import Any

TopicTypes = list[list[str]]
# [publishers, subscribers, services], each a list of [name, [node, ...]] (XML-RPC lists, so Any inside)
SystemState = list[list[list["Any"]]]


class MasterClient:
    """Calls the master at ``uri`` (default ROS_MASTER_URI) as node ``caller_id``."""

    def __init__(
        self, uri: str | None = None, caller_id: str = "/ninjemys", timeout: float | None = 30.0
    ) -> None:
        self.uri = uri or default_master_uri()
        self.caller_id = caller_id
        self.timeout = timeout
        try:
            self._host, self._port = split_uri(self.uri)
        except ValueError as exc:
            raise MasterUnreachable(f"ROS_MASTER_URI: {exc}") from None
        self._sock: socket.socket | None = None
        self._lock = threading.Lock()
        # looked up once: reading the environment on every call cost ~2 us of a ~150 us call
        self._auth = auth.credentials()
        self._trusted: str | None = None  # the caller the open connection is authenticated as

    # ------------------------------------------------------------------------------- transport

    def call_raw(self, method: str, *args: Any) -> Any:
        """One XML-RPC call with ``args`` exactly as given (no caller_id added); returns the raw value."""
        body = wire.dump_call(method, args)
        caller = args[0] if args and isinstance(args[0], str) else ""
        plain = None if self._auth is not None else wire.http_request(self._host, self._port, body)
        with self._lock:
            for attempt in (0, 1):
                fresh = self._sock is None
                try:
                    sock = self._connect()
                    request = plain
                    if request is None:  # authentication on: sign until the connection is trusted
                        signature = (
                            "" if self._trusted == caller else auth.header_line(self._auth, body, caller)
                        )
                        request = wire.http_request(self._host, self._port, body, extra_headers=signature)
                    sock.sendall(request)
                    response = self._read_response(sock)
                    break
                except (ConnectionError, ProtocolError, TimeoutError, OSError) as exc:
                    self._close_locked()
                    if attempt == 0 and not fresh and not isinstance(exc, TimeoutError | socket.timeout):
                        continue  # the master closed our idle keep-alive connection; reconnect once
                    if isinstance(exc, ProtocolError):
                        raise MasterError(f"{method}: master at {self.uri} broke protocol: {exc}") from None
                    raise MasterUnreachable(
                        f"cannot reach the master at {self.uri} ({exc})", cause=exc
                    ) from None
            if response.start[1] != "200":
                self._close_locked()
                raise MasterError(f"{method}: master at {self.uri} answered HTTP {response.start[1]}")
            try:
                result = wire.parse_response(response.body)
            except wire.Fault as fault:
                raise MasterError(f"{method}: XML-RPC fault {fault.faultCode}: {fault.faultString}") from None
            except ProtocolError as exc:
                raise MasterError(f"{method}: {exc}") from None
            finally:
                if not response.keep_alive:
                    self._close_locked()
            if self._auth is not None and self._sock is not None and self._trusted != caller:
                # the master trusts a connection once a signed call on it was accepted (net.auth)
                if not auth.is_refusal(result):
                    self._trusted = caller
            return result

    def call(self, method: str, *args: Any) -> Any:
        """Call ``method(caller_id, *args)`` and unwrap ``[code, status, value]``."""
        result = self.call_raw(method, self.caller_id, *args)
        if not isinstance(result, list) or len(result) != 3 or not isinstance(result[0], int):
            raise MasterError(f"{method}: master answered {result!r}, not [code, status, value]")
        code, status, value = result
        if code != wire.SUCCESS:
            err = MasterError(f"{method}: {status}")
            err.code, err.status, err.method = code, status, method  # type: ignore[attr-defined]
            raise err
        return value

    def _connect(self) -> socket.socket:
        if self._sock is None:
            # a bytes host skips the idna codec (see lookup_host); getaddrinfo takes it, typeshed says str
            address = (lookup_host(self._host), self._port)
            sock = socket.create_connection(address, timeout=self.timeout)  # type: ignore[arg-type]
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._sock = sock
        return self._sock

    def _read_response(self, sock: socket.socket) -> wire.HttpMessage:
        parser = wire.HttpResponseParser()
        while True:
            data = sock.recv(262144)
            if not data:
                raise ConnectionResetError("master closed the connection")
            messages = parser.feed(data)
            if messages:
                return messages[0]

    def _close_locked(self) -> None:
        if self._sock is not None:
            self._trusted = None
            try:
                self._sock.close()
            finally:
                self._sock = None

    def close(self) -> None:
        """Close the keep-alive connection (the next call opens a new one)."""
        with self._lock:
            self._close_locked()

    def __enter__(self) -> MasterClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------------------ master API

    def register_service(self, service: str, service_api: str, caller_api: str) -> int:
        return self.call("registerService", service, service_api, caller_api)

    def unregister_service(self, service: str, service_api: str) -> int:
        return self.call("unregisterService", service, service_api)

    def register_subscriber(self, topic: str, topic_type: str, caller_api: str) -> list[str]:
        """Returns the XML-RPC URIs of the topic's current publishers."""
        return self.call("registerSubscriber", topic, topic_type, caller_api)

    def unregister_subscriber(self, topic: str, caller_api: str) -> int:
        return self.call("unregisterSubscriber", topic, caller_api)

    def register_publisher(self, topic: str, topic_type: str, caller_api: str) -> list[str]:
        """Returns the XML-RPC URIs of the topic's current subscribers."""
        return self.call("registerPublisher", topic, topic_type, caller_api)

    def unregister_publisher(self, topic: str, caller_api: str) -> int:
        return self.call("unregisterPublisher", topic, caller_api)

    def lookup_node(self, node_name: str) -> str:
        return self.call("lookupNode", node_name)

    def lookup_service(self, service: str) -> str:
        return self.call("lookupService", service)

    def get_published_topics(self, subgraph: str = "") -> TopicTypes:
        return self.call("getPublishedTopics", subgraph)

    def get_topic_types(self) -> TopicTypes:
        return self.call("getTopicTypes")

    def get_system_state(self) -> SystemState:
        """``[publishers, subscribers, services]``, each ``[[name, [node, ...]], ...]``."""
        return self.call("getSystemState")

    def get_uri(self) -> str:
        return self.call("getUri")

    def get_pid(self) -> int:
        return self.call("getPid")

    def shutdown(self, message: str = "") -> int:
        """Ask the master to shut down."""
        return self.call("shutdown", message)

    # ---------------------------------------------------------------------- parameter server API

    def get_param(self, key: str) -> Any:
        return self.call("getParam", key)

    def set_param(self, key: str, value: Any) -> int:
        return self.call("setParam", key, value)

    def has_param(self, key: str) -> bool:
        return bool(self.call("hasParam", key))

    def delete_param(self, key: str) -> int:
        return self.call("deleteParam", key)

    def search_param(self, key: str) -> str:
        return self.call("searchParam", key)

    def subscribe_param(self, caller_api: str, key: str) -> Any:
        """Returns the current value, or ``{}`` when the key is not set."""
        return self.call("subscribeParam", caller_api, key)

    def unsubscribe_param(self, caller_api: str, key: str) -> int:
        return self.call("unsubscribeParam", caller_api, key)

    def get_param_names(self) -> list[str]:
        return self.call("getParamNames")

    # --------------------------------------------------------------------------------- helpers

    def is_online(self) -> bool:
        """True if a master answers ``getPid``."""
        try:
            self.get_pid()
        except MasterError:
            return False
        return True
