"""The node's slave XML-RPC API (https://wiki.ros.org/ROS/Slave_API), as rospy answers it.

Methods run on the I/O loop (the XML-RPC server calls them there), so each one only reads state or
hands work off: ``publisherUpdate`` starts connection tasks on the loop, ``paramUpdate`` callbacks
and ``shutdown`` run on helper threads. The rosnode/rostopic/rqt_graph views depend on the exact
shapes of getBusInfo, getBusStats, getPublications and getSubscriptions.
"""

from __future__ import annotations

import logging
import os

from ninjemys.node import shm_link, transport
from ninjemys.wire import xmlrpc as wire

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from typing import Any

    from ninjemys.node.context import NodeContext

_log = logging.getLogger(__name__)


def _caller_ok(caller_id: Any) -> list[Any] | None:
    if not isinstance(caller_id, str):
        return wire.error("caller_id must be a string")
    return None


class SlaveApi:
    """XML-RPC handler object: every public method is an RPC method of the node."""

    def __init__(self, node: NodeContext) -> None:
        self._node = node

    def getUri(self, caller_id: str) -> list[Any]:  # noqa: N802 - ROS 1 method names
        return _caller_ok(caller_id) or wire.ok("", self._node.uri)

    def getName(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("", self._node.name)

    def getMasterUri(self, caller_id: str) -> list[Any]:  # noqa: N802
        if self._node.master_uri:
            return _caller_ok(caller_id) or wire.ok(self._node.master_uri, self._node.master_uri)
        return wire.failure("master URI not set", "")

    def getPid(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("", os.getpid())

    def shutdown(self, caller_id: str, msg: str = "") -> list[Any]:
        err = _caller_ok(caller_id)
        if err:
            return err
        reason = f"external shutdown request from [{caller_id}]: {msg}"
        _log.warning("%s: %s", self._node.name, reason)
        self._node.runtime.start_thread(lambda: self._node.shutdown(reason), "shutdown")
        return wire.ok("shutdown", 0)

    def getPublications(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("publications", self._node.get_publications())

    def getSubscriptions(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("subscriptions", self._node.get_subscriptions())

    def getBusStats(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("", self._node.bus_stats())

    def getBusInfo(self, caller_id: str) -> list[Any]:  # noqa: N802
        return _caller_ok(caller_id) or wire.ok("bus info", self._node.bus_info())

    def paramUpdate(self, caller_id: str, key: str, value: Any) -> list[Any]:  # noqa: N802
        err = _caller_ok(caller_id)
        if err:
            return err
        if not self._node.param_update(key, value):
            return wire.error("not subscribed", 0)
        return wire.ok("", 0)

    def publisherUpdate(self, caller_id: str, topic: str, publishers: list[str]) -> list[Any]:  # noqa: N802
        err = _caller_ok(caller_id)
        if err:
            return err
        if not isinstance(publishers, list) or not all(isinstance(p, str) for p in publishers):
            return wire.error("publishers must be a list of URIs", 0)
        self._node.publisher_update(topic, publishers)
        return wire.ok("", 0)

    def requestTopic(self, caller_id: str, topic: str, protocols: list[Any]) -> list[Any]:  # noqa: N802
        err = _caller_ok(caller_id)
        if err:
            return err
        if not self._node.publishes(topic):
            return wire.error(f"Not a publisher of [{topic}]", [])
        for proto in protocols if isinstance(protocols, list) else []:
            if not isinstance(proto, list) or not proto:
                continue
            unix = self._node.unix_address
            if shm_link.grants(proto):  # SHMROS: large messages through shared memory (shm_link)
                if unix:  # the notices and small messages go over the Unix socket
                    return wire.ok(f"ready on {unix}", [shm_link.SHMROS, unix])
                host, port = self._node.tcpros_host, self._node.tcpros_port
                return wire.ok(f"ready on {host}:{port}", [shm_link.SHMROS, host, port])
            if proto[0] == transport.UNIXROS and unix and proto[1:2] == [transport.host_identity()]:
                return wire.ok(f"ready on {unix}", [transport.UNIXROS, unix])
            if proto[0] == "TCPROS":
                host, port = self._node.tcpros_host, self._node.tcpros_port
                return wire.ok(f"ready on {host}:{port}", ["TCPROS", host, port])
        return wire.failure("no supported protocol implementations", [])
