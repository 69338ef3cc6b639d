"""The ROS graph at one moment: the master's getSystemState, getTopicTypes and getPublishedTopics
answers, indexed once, for every reader.

Every reader of the graph (rosnode, rostopic, rosservice and their facades, shell completion, the
gateway's catalog, rosapi, the graph page's connection graph) asks the master the same three questions
and needs the same lookups: topic -> nodes, the nodes, a node's topics, a topic's type.
:class:`GraphSnapshot` is that answer, frozen: being immutable it can be handed from the gateway's
poll thread to its senders without a lock, and compared with the previous one to find what changed.

It imports nothing but the standard library's ``types`` (not even ``typing``) (shell completion loads it on a 25 ms path,
docs/completion.md), takes the master duck-typed, and builds no dataclasses.
"""

from __future__ import annotations

from types import MappingProxyType

TYPE_CHECKING = False  # typing costs more than the rest of this module on completion's path
if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping, Sequence
    from typing import Any, NoReturn

    Table = Mapping[str, tuple[str, ...]]
    Rows = Iterable[Sequence[Any]] | Mapping[str, Iterable[str]]
    Pairs = Iterable[Sequence[str]] | Mapping[str, str]


def _table(rows: Rows) -> Table:
    items = rows.items() if hasattr(rows, "items") else ((r[0], r[1]) for r in rows)
    return MappingProxyType({str(name): tuple(members) for name, members in items})


def _pairs(rows: Pairs) -> dict[str, str]:
    if hasattr(rows, "items"):
        return {str(k): str(v) for k, v in rows.items()}
    return {str(row[0]): str(row[1]) for row in rows}


class GraphSnapshot:
    """getSystemState, getTopicTypes and getPublishedTopics at one moment, indexed and read-only.

    ``publishers``, ``subscribers`` and ``services`` map a name to the nodes registered for it (in the
    master's order); ``topic_types`` is getTopicTypes (every topic with a known type, subscribed-only
    ones too) and ``published_types`` getPublishedTopics (published topics only), as ROS 1's tools
    tell them apart.
    """

    __slots__ = ("publishers", "subscribers", "services", "topic_types", "published_types")

    publishers: Table
    subscribers: Table
    services: Table
    topic_types: Mapping[str, str]
    published_types: Mapping[str, str]

    def __init__(
        self,
        publishers: Rows = (),
        subscribers: Rows = (),
        services: Rows = (),
        topic_types: Pairs = (),
        published_types: Pairs = (),
    ) -> None:
        set_ = object.__setattr__
        set_(self, "publishers", _table(publishers))
        set_(self, "subscribers", _table(subscribers))
        set_(self, "services", _table(services))
        set_(self, "topic_types", MappingProxyType(_pairs(topic_types)))
        set_(self, "published_types", MappingProxyType(_pairs(published_types)))

    def __setattr__(self, name: str, value: Any) -> NoReturn:
        raise AttributeError(f"GraphSnapshot is read-only (setting {name!r}): fetch a new one")

    @classmethod
    def from_system_state(
        cls, state: Sequence[Sequence[Sequence[Any]]], topic_types: Pairs = (), published_types: Pairs = ()
    ) -> GraphSnapshot:
        """From the master's raw answers (``[pubs, subs, srvs]`` and ``[[topic, type], ...]`` lists)."""
        pubs, subs, srvs = state
        return cls(pubs, subs, srvs, topic_types, published_types)

    @classmethod
    def fetch(cls, master: Any, with_types: bool = True, published: bool = True) -> GraphSnapshot:
        """Ask ``master`` (a :class:`~ninjemys.master.client.MasterClient`) now. ``with_types=False``
        skips both type queries, ``published=False`` only getPublishedTopics (a poller that needs
        getTopicTypes alone saves a round trip)."""
        state = master.get_system_state()
        if not with_types:
            return cls.from_system_state(state)
        published_types = master.get_published_topics("/") if published else ()
        return cls.from_system_state(state, master.get_topic_types(), published_types)

    def same_graph(self, other: GraphSnapshot) -> bool:
        """Whether ``other`` has the same registrations (types aside)."""
        return all(
            dict(getattr(self, a)) == dict(getattr(other, a))
            for a in ("publishers", "subscribers", "services")
        )

    def system_state(self) -> list[list[list[Any]]]:
        """The getSystemState form again (``[[name, [node, ...]], ...]`` three times), for ROS 1 APIs."""
        return [
            [[name, list(nodes)] for name, nodes in table.items()]
            for table in (self.publishers, self.subscribers, self.services)
        ]

    def node_names(self) -> list[str]:
        """Every node with a registration, sorted."""
        nodes: set[str] = set()
        for table in (self.publishers, self.subscribers, self.services):
            for members in table.values():
                nodes.update(members)
        return sorted(nodes)

    def topic_names(self) -> list[str]:
        """Every topic with a publisher or a subscriber, sorted."""
        return sorted({*self.publishers, *self.subscribers})

    def type_of(self, topic: str) -> str | None:
        """The topic's type (getTopicTypes first, then getPublishedTopics), None when unknown."""
        return self.topic_types.get(topic) or self.published_types.get(topic)

    def topics_of(self, node: str) -> tuple[list[str], list[str], list[str]]:
        """(publications, subscriptions, services) of ``node``, each sorted."""
        return (
            sorted(t for t, n in self.publishers.items() if node in n),
            sorted(t for t, n in self.subscribers.items() if node in n),
            sorted(s for s, n in self.services.items() if node in n),
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, GraphSnapshot):
            return NotImplemented
        return all(dict(getattr(self, a)) == dict(getattr(other, a)) for a in self.__slots__)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"GraphSnapshot({len(self.node_names())} nodes, {len(self.publishers)} published topics, "
            f"{len(self.subscribers)} subscribed, {len(self.services)} services)"
        )
