"""Read-only views of the ROS graph shared by rosnode, rostopic and rosservice.

One place that turns the master's getSystemState / getPublishedTopics answers into the lookups the
tools print from, and that talks to a node's slave API (getPid, getBusInfo) with a short timeout so
a dead node costs a clear error line, not a hang.
"""

from __future__ import annotations

import re
import time
from typing import Any

from ninjemys.errors import MasterError, MasterUnreachable
from ninjemys.master.client import MasterClient

#: getBusInfo's optional 7th element, as rospy/roscpp write it
CONNECTION_INFO = re.compile(r"\w+ connection on port (\d+) to \[(.*) on socket (\d+)\]")


class GraphState:
    """getSystemState, indexed: topic -> nodes, node -> topics, plus topic types.

    (A plain class: tools import this on every start, and dataclasses costs ~20 ms to import.)
    """

    def __init__(
        self,
        publishers: dict[str, list[str]] | None = None,
        subscribers: dict[str, list[str]] | None = None,
        services: dict[str, list[str]] | None = None,
    ) -> None:
        self.publishers = publishers or {}
        self.subscribers = subscribers or {}
        self.services = services or {}
        self.published_types: dict[str, str] = {}
        self.topic_types: dict[str, str] = {}

    @classmethod
    def fetch(cls, master: MasterClient, with_types: bool = True) -> GraphState:
        pubs, subs, srvs = master.get_system_state()
        state = cls(
            publishers={t: list(n) for t, n in pubs},
            subscribers={t: list(n) for t, n in subs},
            services={s: list(n) for s, n in srvs},
        )
        if with_types:
            state.published_types = dict(master.get_published_topics("/"))
            state.topic_types = dict(master.get_topic_types())
        return state

    def node_names(self) -> list[str]:
        nodes: set[str] = set()
        for table in (self.publishers, self.subscribers, self.services):
            for members in table.values():
                nodes.update(members)
        return sorted(nodes)

    def type_of(self, topic: str) -> str | None:
        return self.topic_types.get(topic) or self.published_types.get(topic)


def node_api(master: MasterClient, node: str) -> str | None:
    """The node's XML-RPC URI, or None when the master does not know it."""
    try:
        return master.lookup_node(node)
    except MasterError as exc:
        if isinstance(exc, MasterUnreachable):
            raise
        return None


def slave(uri: str, caller_id: str, timeout: float = 3.0) -> MasterClient:
    """A client for a node's slave API (the same keep-alive XML-RPC client the master uses)."""
    return MasterClient(uri, caller_id=caller_id, timeout=timeout)


def ping(uri: str, caller_id: str, timeout: float = 3.0) -> float:
    """One getPid round trip in milliseconds; raises MasterUnreachable/MasterError on failure."""
    client = slave(uri, caller_id, timeout)
    try:
        start = time.perf_counter()
        client.call("getPid")
        return (time.perf_counter() - start) * 1000.0
    finally:
        client.close()


def bus_info(uri: str, caller_id: str, timeout: float = 5.0) -> tuple[int, list[list[Any]]]:
    """(pid, getBusInfo rows) of a node."""
    client = slave(uri, caller_id, timeout)
    try:
        return client.call("getPid"), client.call("getBusInfo")
    finally:
        client.close()
