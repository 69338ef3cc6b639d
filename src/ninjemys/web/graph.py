"""The ROS computation graph as plain data, built from what any ROS 1 master and node answer.

:func:`build_graph` is pure: it turns the master's ``getSystemState`` and ``getTopicTypes`` results
plus each node's ``getBusInfo`` into the JSON the graph page draws. :class:`GraphPoller` fetches those
over XML-RPC with :class:`~ninjemys.master.client.MasterClient` (so real ROS 1 nodes appear exactly
like ours) and reports only real changes.

The ROS 1 master offers no change notifications, so the poller asks it twice a second; bus
information (which connections are up, whether a node still answers) is refreshed less often
because it costs one call per node.
"""

from __future__ import annotations

import hashlib
import json
import logging
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

from ninjemys.errors import MasterError, MasterUnreachable
from ninjemys.master.client import MasterClient

log = logging.getLogger(__name__)

#: Names rqt_graph hides with "Hide Debug": the logging plumbing every node is wired to.
DEBUG_TOPICS = frozenset({"/rosout", "/rosout_agg", "/statistics"})
DEBUG_NODES = frozenset({"/rosout"})


@dataclass(frozen=True)
class Connection:
    """One TCPROS/UDPROS link as a node's getBusInfo reports it."""

    topic: str
    direction: str  # "i" inbound, "o" outbound, "b" both
    peer: str  # caller id (outbound) or publisher URI (inbound), as ROS reports it
    transport: str
    connected: bool


def parse_bus_info(rows: Iterable[list]) -> list[Connection]:
    """Decode getBusInfo rows ``[id, destination, direction, transport, topic, connected, ...]``.

    Rows that do not have that shape (old or foreign implementations) are skipped.
    """
    out = []
    for row in rows:
        if not isinstance(row, list | tuple) or len(row) < 5:
            continue
        connected = bool(row[5]) if len(row) > 5 else True
        out.append(Connection(str(row[4]), str(row[2]), str(row[1]), str(row[3]), connected))
    return out


def namespace_of(name: str) -> str:
    """The namespace a graph name lives in: ``/a/b/c`` -> ``/a/b``, ``/talker`` -> ``/``."""
    head = name.rstrip("/").rsplit("/", 1)[0]
    return head or "/"


def build_graph(
    system_state: list,
    topic_types: list,
    node_uris: dict[str, str],
    bus_info: dict[str, list[Connection] | None],
    own_nodes: frozenset[str] = frozenset(),
) -> dict:
    """Plain-data graph: nodes, topics (with type, publishers, subscribers) and node->node edges.

    ``bus_info[node]`` is None when the node did not answer (shown as unreachable), missing when it was
    not asked yet. ``own_nodes`` (the web tools' own monitor node) count as debug, so "Hide debug"
    keeps the act of looking at a topic out of the picture. An edge is ``connected`` when either end reports a live connection on its topic.
    """
    publishers, subscribers = system_state[0], system_state[1]
    types = {str(t): str(ty) for t, ty in topic_types}
    pubs = {str(t): sorted(str(n) for n in nodes) for t, nodes in publishers}
    subs = {str(t): sorted(str(n) for n in nodes) for t, nodes in subscribers}
    names = set(node_uris)
    for table in (pubs, subs):
        for nodes in table.values():
            names.update(nodes)
    for _topic, nodes in system_state[2] if len(system_state) > 2 else []:
        names.update(str(n) for n in nodes)

    live_topics: dict[str, set[str]] = {}
    for node, conns in bus_info.items():
        for c in conns or []:
            if c.connected:
                live_topics.setdefault(node, set()).add(c.topic)

    nodes = [
        {
            "name": name,
            "namespace": namespace_of(name),
            "uri": node_uris.get(name, ""),
            "reachable": bus_info.get(name, []) is not None,
            "debug": name in DEBUG_NODES or name in own_nodes,
        }
        for name in sorted(names)
    ]
    topics = []
    edges = []
    for topic in sorted(set(pubs) | set(subs) | set(types)):
        p, s = pubs.get(topic, []), subs.get(topic, [])
        topics.append(
            {
                "name": topic,
                "namespace": namespace_of(topic),
                "type": types.get(topic, ""),
                "publishers": p,
                "subscribers": s,
                "debug": topic in DEBUG_TOPICS,
            }
        )
        for a in p:
            for b in s:
                connected = topic in live_topics.get(a, ()) or topic in live_topics.get(b, ())
                edges.append({"source": a, "target": b, "topic": topic, "connected": connected})
    graph = {"nodes": nodes, "topics": topics, "edges": edges}
    graph["version"] = hashlib.sha1(json.dumps(graph, sort_keys=True).encode()).hexdigest()[:16]
    return graph


class GraphPoller:
    """Polls a master (and its nodes) on a thread; calls ``on_change(graph)`` whenever the graph differs.

    ``on_error(message)`` is told when the master cannot be reached (once per outage).
    """

    def __init__(
        self,
        master_uri: str,
        caller_id: str,
        on_change: Callable[[dict], None],
        on_error: Callable[[str], None] | None = None,
        own_nodes: Callable[[], frozenset[str]] = frozenset,
        period: float = 0.5,
        bus_period: float = 2.0,
        timeout: float = 2.0,
    ) -> None:
        self.master_uri = master_uri
        self.caller_id = caller_id
        self.period = period
        self.bus_period = bus_period
        self.timeout = timeout
        self._on_change = on_change
        self._on_error = on_error or (lambda _m: None)
        self._own_nodes = own_nodes
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None
        self._pool = ThreadPoolExecutor(max_workers=8, thread_name_prefix="graph-bus")
        # bus sweeps run beside the master poll, so a slow sweep never delays a graph change
        self._sweeper = ThreadPoolExecutor(max_workers=1, thread_name_prefix="graph-sweep")
        self._sweep: Future | None = None
        self._bus_lock = threading.Lock()
        self._master = MasterClient(master_uri, caller_id, timeout=timeout)
        self._uris: dict[str, str] = {}
        self._bus: dict[str, list[Connection] | None] = {}
        self._bus_time = 0.0
        self._names: list[str] = []
        self.graph: dict | None = None
        self.master_ok = True

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="graph-poller", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=self.timeout + 1.0)
        self._sweeper.shutdown(wait=False, cancel_futures=True)
        self._master.close()
        self._pool.shutdown(wait=False, cancel_futures=True)

    def refresh(self) -> None:
        """Poll now instead of at the next tick (e.g. the user pressed refresh)."""
        self._wake.set()

    def poll_once(self, now: float) -> dict | None:
        """One round: the new graph if it changed, else None. Raises MasterError when the master fails."""
        master = self._master
        state = master.call("getSystemState")
        try:
            types = master.call("getTopicTypes")
        except MasterUnreachable:
            raise
        except MasterError:
            types = []
        names = set()
        for table in state[:3]:
            for _t, nodes in table:
                names.update(nodes)
        unknown = sorted(names - set(self._uris))

        for name in unknown:  # one keep-alive connection: a lookup is a round trip, not a connect
            try:
                self._uris[name] = str(master.call("lookupNode", name))
            except MasterUnreachable:
                raise
            except MasterError:
                continue  # gone between getSystemState and now
        with self._bus_lock:
            for gone in (set(self._uris) | set(self._bus)) - names:
                self._uris.pop(gone, None)
                self._bus.pop(gone, None)
            bus = dict(self._bus)
        self._names = sorted(names)
        graph = build_graph(state, types, dict(self._uris), bus, self._own_nodes())
        if self.graph is not None and graph["version"] == self.graph["version"]:
            return None
        self.graph = graph
        return graph

    def _refresh_bus(self, names: list[str]) -> None:
        def ask(name: str) -> tuple[str, list[Connection] | None]:
            uri = self._uris.get(name)
            if not uri:
                return name, None
            # the slave API uses the master's [code, status, value] convention
            try:
                with MasterClient(uri, self.caller_id, timeout=self.timeout) as node:
                    rows = node.call("getBusInfo")
            except MasterUnreachable:
                return name, None
            except MasterError:
                return name, []
            return name, parse_bus_info(rows if isinstance(rows, list) else [])

        for name, conns in self._pool.map(ask, names):
            with self._bus_lock:
                self._bus[name] = conns

    def _start_sweep(self, names: list[str]) -> None:
        if self._sweep is not None and not self._sweep.done():
            return
        try:
            self._sweep = self._sweeper.submit(self._refresh_bus, names)
        except RuntimeError:  # stopping
            return
        self._sweep.add_done_callback(lambda _f: self._wake.set())

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                graph = self.poll_once(time.monotonic())
            except (MasterError, ValueError, TypeError) as exc:
                if self.master_ok:
                    self.master_ok = False
                    self._on_error(f"cannot reach the master at {self.master_uri}: {exc}")
            else:
                if not self.master_ok:
                    self.master_ok = True
                    graph = graph or self.graph
                if graph is not None:
                    self._on_change(graph)
                # connection states cost one call per node: swept beside the poll, and less often
                now = time.monotonic()
                with self._bus_lock:
                    fresh = [n for n in self._names if n not in self._bus]
                if now - self._bus_time >= self.bus_period:
                    self._bus_time = now
                    self._start_sweep(self._names)
                elif fresh:
                    self._start_sweep(fresh)
            self._wake.wait(self.period)
            self._wake.clear()
