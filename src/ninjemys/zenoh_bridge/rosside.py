"""The local ROS graph as the bridge sees it: who publishes, subscribes and serves what, with types.

``getSystemState`` names the topics and nodes; the datatype and md5 come from the other side of a
connection header, as the Rust bridge learns them: a publisher is asked with ``requestTopic`` and a
TCPROS header exchange with md5 ``*`` (it answers with its type, md5 and definition, then we close);
a service with a TCPROS probe. A subscriber's type is what it registered (``getTopicTypes``); its md5
is the local definition's (ROS 1 subscribers do not say their md5 until something connects to
them); one of a type unknown here is bridged when a remote publisher of the topic is announced. The bridge's own node is left out of everything.
"""

from __future__ import annotations

import logging
import socket
from collections.abc import Iterable
from dataclasses import dataclass, field

from ninjemys.errors import NinjemysError
from ninjemys.master.client import MasterClient
from ninjemys.net import auth
from ninjemys.node.services import probe as probe_service
from ninjemys.wire import headers
from ninjemys.zenoh_bridge.keys import Resource

_log = logging.getLogger("ninjemys.zenoh_bridge")

PROBE_TIMEOUT = 2.0


@dataclass
class GraphState:
    """One reading of the master: the resources whose type and md5 are known."""

    publishers: set[Resource] = field(default_factory=set)
    subscribers: set[Resource] = field(default_factory=set)
    services: set[Resource] = field(default_factory=set)


def probe_publisher(
    node_uri: str, topic: str, caller_id: str, timeout: float = PROBE_TIMEOUT
) -> dict[str, str]:
    """The connection header ``node_uri``'s publisher of ``topic`` sends to a subscriber of type ``*``."""
    code, status, proto = auth.server_proxy(node_uri).requestTopic(caller_id, topic, [["TCPROS"]])
    if code != 1 or not proto or proto[0] != "TCPROS":
        raise NinjemysError(f"publisher {node_uri} of {topic} declined TCPROS: {status}")
    with socket.create_connection((proto[1], int(proto[2])), timeout=timeout) as sock:
        fields = {"callerid": caller_id, "topic": topic, "md5sum": "*", "type": "*", "tcp_nodelay": "1"}
        sock.sendall(headers.encode_header(auth.sign_fields(fields)))
        prefix = _recv_exact(sock, 4)
        reply = headers.decode_header(_recv_exact(sock, headers.header_length(prefix)))
    if "error" in reply:
        raise NinjemysError(f"publisher {node_uri} of {topic}: {reply['error']}")
    return reply


def _recv_exact(sock: socket.socket, n: int) -> bytes:
    buf = bytearray()
    while len(buf) < n:
        chunk = sock.recv(n - len(buf))
        if not chunk:
            raise NinjemysError("connection closed during the header exchange")
        buf += chunk
    return bytes(buf)


def local_md5(datatype: str) -> str | None:
    """The md5 of ``datatype`` from the definitions on this machine, None when it has none."""
    from ninjemys.idl.loader import get_message_md5

    try:
        return get_message_md5(datatype)
    except Exception:  # unknown package or message: the remote side will tell
        return None


def local_definition(datatype: str) -> str | None:
    from ninjemys.idl.loader import get_full_text

    try:
        return get_full_text(datatype)
    except Exception:
        return None


class LocalGraph:
    """Reads the master and caches what probes learned, per (topic, node) and (service, URI)."""

    def __init__(self, master: MasterClient, own_name: str) -> None:
        self.master = master
        self.own_name = own_name
        self._pub_cache: dict[tuple[str, str], dict[str, str]] = {}
        self._srv_cache: dict[tuple[str, str], dict[str, str]] = {}
        #: the last header seen from a publisher of each topic (definition, latching)
        self.publisher_headers: dict[str, dict[str, str]] = {}

    def read(self) -> GraphState:
        """One poll: raises :class:`NinjemysError` (or OSError) when the master cannot be read."""
        pubs, subs, srvs = self.master.get_system_state()
        types = dict(self.master.get_topic_types())
        state = GraphState()
        live_pub_keys = set()
        for topic, nodes in pubs:
            for node in self._others(nodes):
                live_pub_keys.add((topic, node))
                header = self._publisher_header(topic, node)
                if header is not None:
                    state.publishers.add(Resource(topic, header.get("type", ""), header.get("md5sum", "")))
                    self.publisher_headers[topic] = header
        for stale in set(self._pub_cache) - live_pub_keys:
            del self._pub_cache[stale]
        live_topics = {topic for topic, _ in live_pub_keys}
        for topic in set(self.publisher_headers) - live_topics:
            del self.publisher_headers[topic]
        for topic, nodes in subs:
            if not list(self._others(nodes)):
                continue
            datatype = types.get(topic, "*")
            md5 = local_md5(datatype) if datatype != "*" else None
            if md5 is not None:  # else a remote publisher's announcement brings the bridge
                state.subscribers.add(Resource(topic, datatype, md5))
        live_srv = set()
        for service, nodes in srvs:
            provider = next(iter(self._others(nodes)), None)
            if provider is None:
                continue
            live_srv.add((service, provider))
            header = self._service_header(service, provider)
            if header is not None:
                state.services.add(Resource(service, header.get("type", ""), header.get("md5sum", "")))
        for stale in [k for k in self._srv_cache if k not in live_srv]:
            del self._srv_cache[stale]
        return state

    def _others(self, nodes: Iterable[str]) -> Iterable[str]:
        return (n for n in nodes if n != self.own_name)

    def _publisher_header(self, topic: str, node: str) -> dict[str, str] | None:
        cached = self._pub_cache.get((topic, node))
        if cached is not None:
            return cached
        try:
            uri = self.master.lookup_node(node)
            header = probe_publisher(uri, topic, self.own_name)
        except (OSError, NinjemysError) as exc:
            _log.info("cannot learn the type of %s from %s (tried again next poll): %s", topic, node, exc)
            return None
        self._pub_cache[(topic, node)] = header
        return header

    def _service_header(self, service: str, node: str) -> dict[str, str] | None:
        """Probed once per (service, provider node): a poll costs no master call per service."""
        cached = self._srv_cache.get((service, node))
        if cached is not None:
            return cached
        try:
            uri = self.master.lookup_service(service)
            header = probe_service(service, uri, timeout=PROBE_TIMEOUT, caller_id=self.own_name)
        except (OSError, NinjemysError) as exc:
            _log.info("cannot learn the type of service %s: %s", service, exc)
            return None
        if "error" in header:
            return None
        self._srv_cache[(service, node)] = header
        return header
