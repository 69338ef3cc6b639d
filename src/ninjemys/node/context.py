"""NodeContext: the one interface through which a node's parts reach their node.

A :class:`~ninjemys.node.Node` is made of parts: publications (``topics``), subscriptions
(``subscriber``), service servers and proxies (``services``), the registrar (``registration``) and the
slave XML-RPC API (``slave``). Each part holds a ``NodeContext``, never a ``Node``: what a part may
read (names, URIs, the I/O runtime, the master client) and which calls it may make back (a handle
released, a connection closed, a master notification to route) is exactly this Protocol, so the
Node's internals can change without touching its parts, and the parts can be tested on a stand-in.

The parts import this module only for type checking (``typing`` costs start-up time); the type
checker proves that ``Node`` satisfies it wherever a part is built with ``self``, and
``tests/node/test_node_context.py`` checks the same at run time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from ninjemys.master.client import MasterClient
    from ninjemys.node.log import NodeLog
    from ninjemys.node.runtime import Runtime
    from ninjemys.node.services import ServiceServer
    from ninjemys.node.subscriber import Subscriber
    from ninjemys.node.topics import PubConnection, Publisher


class NodeContext(Protocol):
    """What a node's parts may use of their node."""

    #: the node's resolved global name (the ``callerid`` of every header and XML-RPC call)
    name: str
    #: the node's slave XML-RPC URI
    uri: str
    master_uri: str
    #: the node's client of the master's XML-RPC API (thread-safe)
    master: MasterClient
    #: the process's I/O loop and its thread hand-offs
    runtime: Runtime
    #: the node's console, log file and /rosout logger
    log: NodeLog
    #: where the node's TCPROS server listens, as advertised to peers
    tcpros_host: str
    tcpros_port: int
    unix_address: str | None  # the UNIXROS listener (node.transport), None without one

    @property
    def is_shutdown(self) -> bool: ...

    def wait_for_shutdown(self, timeout: float | None = None) -> bool: ...

    def shutdown(self, reason: str = "") -> None: ...

    # -- calls back from the parts ------------------------------------------------------------------

    def release_publisher(self, handle: Publisher) -> None:
        """A Publisher handle was unregistered (the last one of a topic unregisters the topic)."""
        ...

    def release_subscriber(self, handle: Subscriber) -> None:
        """A Subscriber handle was unregistered (the last one of a topic unregisters the topic)."""
        ...

    def release_service(self, server: ServiceServer) -> None:
        """A service server was shut down by its owner."""
        ...

    def connection_closed(self, conn: PubConnection) -> None:
        """A subscriber's connection to one of our publications ended (called on the I/O loop)."""
        ...

    def publisher_update(self, topic: str, publishers: list[str], updates: int | None = None) -> None:
        """The master says these are now the publishers of ``topic`` (slave API, re-registration);
        ``updates``: an answer to registerSubscriber sent when :meth:`publisher_updates` said that."""
        ...

    def publisher_updates(self, topic: str) -> int:
        """How many publisher lists the subscription of ``topic`` has applied."""
        ...

    def param_update(self, key: str, value: Any) -> bool:
        """A subscribed parameter changed (slave API); False when nothing here subscribes ``key``."""
        ...

    def publishes(self, topic: str) -> bool:
        """True when this node publishes ``topic`` (slave ``requestTopic``)."""
        ...

    def get_publications(self) -> list[list[str]]: ...

    def get_subscriptions(self) -> list[list[str]]: ...

    def bus_stats(self) -> list[Any]: ...

    def bus_info(self) -> list[Any]: ...
