"""The web tools app against a real ROS 1 graph: Debian's rosmaster and rospy talker/listener."""

from __future__ import annotations

import json
import signal
import urllib.request

import pytest
from web_helpers import LISTENER, TALKER, wait_until

from ninjemys.web.app import WebApp

pytestmark = pytest.mark.ros1


def _get(url: str) -> dict:
    with urllib.request.urlopen(url, timeout=5) as resp:
        return json.load(resp)


@pytest.fixture
def app(ros1_master: str):  # type: ignore[no-untyped-def]
    web = WebApp(ros1_master, caller_id="/test_rqt_graph", poll_period=0.2)
    web.start()
    try:
        yield web
    finally:
        web.stop()


def _edge(graph: dict | None, source: str, target: str) -> bool:
    return bool(graph) and any(e["source"] == source and e["target"] == target for e in graph["edges"])


def test_graph_shows_real_ros1_nodes_and_follows_changes(app: WebApp, rospy_node) -> None:  # type: ignore[no-untyped-def]
    rospy_node(TALKER)
    listener = rospy_node(LISTENER)
    graph = wait_until(
        lambda: (g := _get(app.url + "api/graph")["graph"]) and _edge(g, "/talker", "/listener") and g,
        what="talker -> listener edge",
    )
    chatter = next(t for t in graph["topics"] if t["name"] == "/chatter")
    assert chatter["type"] == "std_msgs/String"
    assert wait_until(lambda: _edge(_get(app.url + "api/graph")["graph"], "/talker", "/listener"))
    details = _get(app.url + "api/topic?name=/chatter")
    assert details["publishers"] == ["/talker"] and details["subscribers"] == ["/listener"]

    listener.send_signal(signal.SIGINT)  # rospy unregisters on shutdown
    listener.wait(10)
    wait_until(
        lambda: all(n["name"] != "/listener" for n in _get(app.url + "api/graph")["graph"]["nodes"]),
        what="listener to leave the graph",
    )


def test_unknown_topic_is_a_404(app: WebApp) -> None:
    with pytest.raises(urllib.error.HTTPError) as info:
        urllib.request.urlopen(app.url + "api/topic?name=/nope", timeout=5)
    assert info.value.code == 404


def test_unreachable_master_is_reported() -> None:
    from ninjemys.testing import free_port

    web = WebApp(f"http://localhost:{free_port()}/", poll_period=0.2)
    web.start()
    try:
        state = wait_until(lambda: _get(web.url + "api/graph").get("error"), what="master error")
        assert "cannot reach the master" in state
    finally:
        web.stop()


def test_topic_details_show_rate_and_last_message(ros1_master: str, rospy_node) -> None:  # type: ignore[no-untyped-def]
    from ninjemys.node import Node
    from ninjemys.web.monitor import TopicMonitor

    monitor = TopicMonitor(lambda: Node("test_webtools", anonymous=True, master_uri=ros1_master))
    web = WebApp(ros1_master, caller_id="/test_rqt_graph", poll_period=0.2, monitor=monitor)
    web.start()
    try:
        rospy_node(TALKER)
        wait_until(
            lambda: any(
                t["name"] == "/chatter"
                for t in (_get(web.url + "api/graph")["graph"] or {}).get("topics", [])
            ),
            what="/chatter in the graph",
        )
        details = wait_until(
            lambda: (d := _get(web.url + "api/topic?name=/chatter"))["count"] >= 5 and d, what="messages"
        )
        assert details["type"] == "std_msgs/String"
        assert details["last_message"] == 'data: "hello world"'
        assert 2.0 < details["rate"] < 50.0  # the talker publishes at 10 Hz (loose: shared machine)
    finally:
        web.stop()
