"""Which ROS connections are up and which nodes answer: the gateway's ROS extension of the
Foxglove connection graph, for the graph page (rqt_graph in the browser).

The master knows who publishes and subscribes (the standard ``connectionGraphUpdate``), but not
whether a node still answers or whether a publisher and a subscriber are actually connected; each
node's ``getBusInfo`` tells. Asking costs one XML-RPC call per node, so :class:`BusWatch` sweeps only
while some client watches the connection graph, at most every ``period`` seconds, beside the
gateway's own graph poll, and reports only changes. It speaks to real ROS 1 nodes exactly as to
ours (the slave API over XML-RPC).

The result (:meth:`BusWatch.state`) is plain data::

    {"nodes": {"/talker": {"uri": "http://h:1/", "reachable": true}, ...},
     "live": {"/talker": ["/chatter"], ...}}     # topics with a live connection, per node
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

from ninjemys.errors import MasterError, MasterUnreachable
from ninjemys.master.client import MasterClient


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


def bus_state(uris: dict[str, str], bus: dict[str, list[Connection] | None]) -> dict[str, Any]:
    """The plain-data form sent to the pages: reachability per node, live topics per node."""
    live = {}
    for name, conns in sorted(bus.items()):
        topics = sorted({c.topic for c in conns or [] if c.connected})
        if topics:
            live[name] = topics
    nodes = {
        name: {"uri": uris.get(name, ""), "reachable": bus.get(name, []) is not None}
        for name in sorted(set(uris) | set(bus))
    }
    return {"nodes": nodes, "live": live}


class BusWatch:
    """Sweeps ``getBusInfo`` of the graph's nodes on ``pool``; ``on_change(state)`` after a sweep
    that changed something. :meth:`poke` (from the gateway's poll) starts a sweep when one is due."""

    def __init__(
        self,
        master: Any,
        caller_id: str,
        pool: Executor,
        on_change: Callable[[dict[str, Any]], None],
        period: float = 2.0,
        timeout: float = 2.0,
    ) -> None:
        self._master = master
        self._caller_id = caller_id
        self._pool = pool
        self._on_change = on_change
        self.period = period
        self.timeout = timeout
        self._uris: dict[str, str] = {}
        self._bus: dict[str, list[Connection] | None] = {}
        self._last = -1e9
        self._running = False
        self._lock = threading.Lock()
        self._state: dict[str, Any] = {"nodes": {}, "live": {}}

    def state(self) -> dict[str, Any]:
        with self._lock:
            return self._state

    def poke(self, names: set[str], force: bool = False) -> None:
        """Sweep ``names`` now if the last sweep is ``period`` old, a node is new, or ``force``."""
        now = time.monotonic()
        with self._lock:
            if self._running:
                return
            fresh = bool(names - set(self._bus))
            if not (force or fresh or now - self._last >= self.period):
                return
            self._running = True
            self._last = now
        try:
            self._pool.submit(self._sweep, sorted(names))
        except RuntimeError:  # the gateway is shutting down
            with self._lock:
                self._running = False

    def _ask(self, name: str) -> list[Connection] | None:
        uri = self._uris.get(name)
        if uri is None:
            try:
                uri = self._uris[name] = str(self._master.lookup_node(name))
            except MasterError:
                return None  # gone between the graph poll and now
        # the slave API uses the master's [code, status, value] convention
        try:
            with MasterClient(uri, self._caller_id, timeout=self.timeout) as node:
                rows = node.call("getBusInfo")
        except MasterUnreachable:
            return None
        except MasterError:
            return []
        return parse_bus_info(rows if isinstance(rows, list) else [])

    def _sweep(self, names: list[str]) -> None:
        try:
            bus = {name: self._ask(name) for name in names}
            for gone in set(self._uris) - set(names):
                del self._uris[gone]
            state = bus_state({n: u for n, u in self._uris.items()}, bus)
            with self._lock:
                changed = state != self._state
                self._bus, self._state = bus, state
        finally:
            with self._lock:
                self._running = False
        if changed:
            self._on_change(state)
