"""build_graph: system state + topic types + bus info -> the JSON the graph page draws."""

from __future__ import annotations

from ninjemys.web.graph import Connection, build_graph, namespace_of, parse_bus_info

STATE = [
    [["/chatter", ["/talker"]], ["/rosout", ["/talker", "/listener"]], ["/robot/odom", ["/robot/base"]]],
    [["/chatter", ["/listener"]], ["/rosout", ["/rosout"]]],
    [["/talker/get_loggers", ["/talker"]]],
]
TYPES = [
    ["/chatter", "std_msgs/String"],
    ["/rosout", "rosgraph_msgs/Log"],
    ["/robot/odom", "nav_msgs/Odometry"],
]


def test_nodes_topics_edges() -> None:
    g = build_graph(STATE, TYPES, {"/talker": "http://h:1/"}, {})
    assert [n["name"] for n in g["nodes"]] == ["/listener", "/robot/base", "/rosout", "/talker"]
    chatter = next(t for t in g["topics"] if t["name"] == "/chatter")
    assert chatter == {
        "name": "/chatter",
        "namespace": "/",
        "type": "std_msgs/String",
        "publishers": ["/talker"],
        "subscribers": ["/listener"],
        "debug": False,
    }
    assert {"source": "/talker", "target": "/listener", "topic": "/chatter", "connected": False} in g["edges"]
    assert next(t for t in g["topics"] if t["name"] == "/rosout")["debug"] is True
    assert next(n for n in g["nodes"] if n["name"] == "/robot/base")["namespace"] == "/robot"


def test_bus_info_marks_connections_and_unreachable_nodes() -> None:
    bus = {"/talker": [Connection("/chatter", "o", "/listener", "TCPROS", True)], "/listener": None}
    g = build_graph(STATE, TYPES, {}, bus)
    edge = next(e for e in g["edges"] if e["topic"] == "/chatter")
    assert edge["connected"] is True
    assert next(n for n in g["nodes"] if n["name"] == "/listener")["reachable"] is False


def test_version_changes_only_with_content() -> None:
    a = build_graph(STATE, TYPES, {}, {})
    b = build_graph(STATE, TYPES, {}, {})
    c = build_graph([STATE[0][:1], STATE[1], STATE[2]], TYPES, {}, {})
    assert a["version"] == b["version"] != c["version"]


def test_parse_bus_info_tolerates_odd_rows() -> None:
    rows = [
        [1, "/listener", "o", "TCPROS", "/chatter", True, "info"],
        ["bogus"],
        [2, "http://x:1/", "i", "TCPROS", "/a"],
    ]
    assert parse_bus_info(rows) == [
        Connection("/chatter", "o", "/listener", "TCPROS", True),
        Connection("/a", "i", "http://x:1/", "TCPROS", True),
    ]


def test_namespace_of() -> None:
    assert namespace_of("/talker") == "/"
    assert namespace_of("/a/b/c") == "/a/b"


def test_own_nodes_count_as_debug() -> None:
    g = build_graph(STATE, TYPES, {}, {}, own_nodes=frozenset({"/listener"}))
    assert next(n for n in g["nodes"] if n["name"] == "/listener")["debug"] is True
