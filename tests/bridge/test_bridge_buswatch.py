"""The gateway's bus watch: getBusInfo rows -> which nodes answer and which connections are up
(the rosBus extension of the connection graph the graph page draws)."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

from ninjemys.bridge.buswatch import BusWatch, Connection, bus_state, parse_bus_info
from ninjemys.errors import MasterError


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


def test_bus_state_marks_live_topics_and_unreachable_nodes() -> None:
    bus = {
        "/talker": [Connection("/chatter", "o", "/listener", "TCPROS", True)],
        "/idle": [Connection("/x", "o", "/y", "TCPROS", False)],
        "/listener": None,
    }
    state = bus_state({"/talker": "http://h:1/"}, bus)
    assert state["live"] == {"/talker": ["/chatter"]}
    assert state["nodes"]["/talker"] == {"uri": "http://h:1/", "reachable": True}
    assert state["nodes"]["/listener"]["reachable"] is False
    assert state["nodes"]["/idle"]["reachable"] is True


class _Master:
    def lookup_node(self, name: str) -> str:
        raise MasterError(f"unknown node {name}")


def test_a_node_gone_before_the_sweep_is_unreachable_and_reported_once() -> None:
    seen: list[dict] = []
    with ThreadPoolExecutor(1) as pool:
        watch = BusWatch(_Master(), "/test", pool, seen.append, period=60.0)
        watch.poke({"/ghost"})
        watch.poke({"/ghost"})  # a sweep is running or was just made: not again
    assert seen == [{"nodes": {"/ghost": {"uri": "", "reachable": False}}, "live": {}}]
    with ThreadPoolExecutor(1) as pool:
        watch._pool = pool
        watch.poke({"/ghost"}, force=True)  # forced, and nothing changed: no report
    assert len(seen) == 1
