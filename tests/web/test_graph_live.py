"""The graph page's data against a real ROS 1 graph (Debian's rosmaster, rospy talker/listener),
read as the page reads it: the gateway's Foxglove connection graph with its rosBus extension."""

from __future__ import annotations

import json
import signal

import pytest
from web_helpers import LISTENER, TALKER, graph_app
from websockets.sync.client import ClientConnection, connect

from ninjemys.testing import wait_until

pytestmark = pytest.mark.ros1


class GraphClient:
    """A Foxglove client that keeps the connection graph as the page does (and the last status)."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws
        self.pub: dict[str, list[str]] = {}
        self.sub: dict[str, list[str]] = {}
        self.bus: dict = {"nodes": {}, "live": {}}
        self.types: dict[str, str] = {}
        self.status: dict | None = None
        self.info: dict = {}
        self.ws.send(json.dumps({"op": "subscribeConnectionGraph"}))

    def pump(self) -> None:
        while True:
            try:
                raw = self.ws.recv(timeout=0.2)
            except TimeoutError:
                return
            if isinstance(raw, bytes):
                continue
            msg = json.loads(raw)
            op = msg["op"]
            if op == "serverInfo":
                self.info = msg
            elif op == "advertise":
                self.types.update({c["topic"]: c["schemaName"] for c in msg["channels"]})
            elif op == "status":
                self.status = msg
            elif op == "removeStatus":
                self.status = None
            elif op == "connectionGraphUpdate":
                self.pub.update({t["name"]: t["publisherIds"] for t in msg["publishedTopics"]})
                self.sub.update({t["name"]: t["subscriberIds"] for t in msg["subscribedTopics"]})
                for name in msg["removedTopics"]:
                    self.pub.pop(name, None)
                    self.sub.pop(name, None)
                self.bus = msg.get("rosBus", self.bus)

    def edge_live(self, source: str, target: str, topic: str) -> bool:
        self.pump()
        linked = source in self.pub.get(topic, []) and target in self.sub.get(topic, [])
        live = self.bus["live"]
        return linked and (topic in live.get(source, []) or topic in live.get(target, []))


def _connect(url: str) -> ClientConnection:
    return connect(url.replace("http", "ws", 1) + "ws", subprotocols=["foxglove.websocket.v1"])


def test_graph_shows_real_ros1_nodes_and_follows_changes(ros1_master: str, rospy_node) -> None:  # type: ignore[no-untyped-def]
    with graph_app(ros1_master) as app, _connect(app.url) as ws:
        client = GraphClient(ws)
        rospy_node(TALKER)
        listener = rospy_node(LISTENER)
        wait_until(
            lambda: client.edge_live("/talker", "/listener", "/chatter"), what="live talker -> listener"
        )
        assert client.types["/chatter"] == "std_msgs/String"
        assert client.bus["nodes"]["/talker"]["reachable"] is True
        assert client.info["metadata"]["ROS_MASTER_URI"] == ros1_master
        # the gateway's own node is the act of looking: the page counts it as debug
        assert client.info["metadata"]["debugNodes"].startswith("/test_rqt_graph")
        listener.send_signal(signal.SIGINT)  # rospy unregisters on shutdown
        listener.wait(10)
        wait_until(
            lambda: (client.pump(), "/listener" not in client.sub.get("/chatter", []))[1],
            what="listener to leave the graph",
        )


def test_unreachable_master_is_reported() -> None:
    from ninjemys.testing import free_port

    with graph_app(f"http://localhost:{free_port()}/") as app, _connect(app.url) as ws:
        client = GraphClient(ws)
        status = wait_until(lambda: (client.pump(), client.status)[1], what="master status")
        assert status["id"] == "master" and status["level"] == 2
        assert "cannot reach the master" in status["message"]
