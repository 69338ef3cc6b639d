"""The slave XML-RPC API answers as rospy does (shapes rosnode/rostopic/rqt_graph rely on)."""

from __future__ import annotations

import os
import xmlrpc.client

from node_msgs import String

from ninjemys.node import shm_link, transport
from ninjemys.testing import wait_until


def test_slave_api_shapes(make_node, master) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    listener.subscriber("chatter", String, lambda m: None)
    pub = talker.publisher("chatter", String)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(String("x"))
    api = xmlrpc.client.ServerProxy(talker.uri)
    assert api.getPid("/t") == [1, "", os.getpid()]
    assert api.getMasterUri("/t")[2] == master.uri
    assert api.getUri("/t")[2] == talker.uri
    assert api.getName("/t")[2] == "/talker"
    assert ["/chatter", "std_msgs/String"] in api.getPublications("/t")[2]
    assert xmlrpc.client.ServerProxy(listener.uri).getSubscriptions("/t")[2] == [
        ["/chatter", "std_msgs/String"]
    ]
    code, _, info = api.getBusInfo("/t")
    chatter_info = [entry for entry in info if entry[4] == "/chatter"]
    # two ninjemys nodes of one host talk over a Unix socket (UNIXROS); getBusInfo names the transport
    local = "UNIXROS" if transport.local_transport_enabled() else "TCPROS"
    local = "SHMROS" if shm_link.enabled() else local  # offered first (tests/node/test_shm.py)
    assert code == 1 and chatter_info[0][1:6] == ["/listener", "o", local, "/chatter", True]
    assert chatter_info[0][6] == f"{local} connection to [/listener]"
    code, _, (pubstats, substats, _srv) = api.getBusStats("/t")
    chatter = {stat[0]: stat for stat in pubstats}["/chatter"]  # next to the node's own /rosout
    assert chatter[1] > 0
    code, msg, proto = api.requestTopic("/t", "/chatter", [["UDPROS"], ["TCPROS"]])
    assert code == 1 and proto[0] == "TCPROS" and proto[2] == talker.tcpros_port
    assert api.requestTopic("/t", "/nothing", [["TCPROS"]])[0] == -1
    # UNIXROS only for this host (boot id and network namespace); anyone else falls through to TCPROS
    if transport.local_transport_enabled():
        code, _, proto = api.requestTopic(
            "/t", "/chatter", [["UNIXROS", transport.host_identity()], ["TCPROS"]]
        )
        assert code == 1 and proto == ["UNIXROS", f"@ninjemys-tcpros-{talker.tcpros_port}"]
        code, _, proto = api.requestTopic("/t", "/chatter", [["UNIXROS", "another-host/1"], ["TCPROS"]])
        assert code == 1 and proto[0] == "TCPROS"
        assert api.requestTopic("/t", "/chatter", [["UNIXROS"]])[0] == 0
    assert api.requestTopic("/t", "/chatter", [["UDPROS"]])[0] == 0
    assert api.paramUpdate("/master", "/not/subscribed/", 1)[0] == -1
    assert api.getPid(42)[0] == -1


def test_param_update_dispatch_and_private_params(make_node, master) -> None:
    node = make_node("watcher", params={"gain": 2.5})
    assert node.get_param("~gain") == 2.5
    assert node.get_param("/watcher/gain") == 2.5
    assert node.get_param("missing", "dflt") == "dflt"
    seen: list[tuple[str, object]] = []
    node.subscribe_param("~gain", lambda k, v: seen.append((k, v)))
    other = make_node("setter")
    other.set_param("/watcher/gain", 7)
    assert wait_until(lambda: seen == [("/watcher/gain", 7)])


def test_shutdown_call_stops_the_node(make_node) -> None:
    node = make_node("victim")
    assert xmlrpc.client.ServerProxy(node.uri).shutdown("/killer", "test")[0] == 1
    assert node.wait_for_shutdown(5)
    assert "external shutdown request" in node.shutdown_reason


def test_name_collision_shuts_down_the_old_node(make_node) -> None:
    old = make_node("same")
    old.publisher("chatter", String)
    new = make_node("same")
    new.publisher("chatter", String)
    assert old.wait_for_shutdown(5)
    assert not new.is_shutdown
