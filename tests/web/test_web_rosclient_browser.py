"""The browser's ROS client (static/lib/rosclient.js) against the gateway: publish, services,
parameters, a type nobody advertises, and reconnection with the subscriptions kept."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import wait_until
from ninjemys.web.app import WebApp

pytestmark = pytest.mark.browser

SETUP = """
async () => {
  const { RosClient } = await import('/static/lib/rosclient.js');
  window.ros = new RosClient();
  window.got = [];
  window.closes = 0;
  ros.on('close', () => closes++);
  await ros.ready();
  ros.subscribe('/counter', (m) => got.push(m.data), { type: 'std_msgs/Int32' });
  return true;
}
"""


@pytest.fixture
def served() -> Iterator[dict[str, Any]]:
    with MasterThread() as uri:
        peer = Node("rosclient_peer", anonymous=True, master_uri=uri)
        gateway = Gateway(GatewayOptions(update_period=0.2), node=Node("gw", anonymous=True, master_uri=uri))
        gateway.start()
        app = WebApp(uri)
        app.add_gateway(gateway)
        try:
            yield {"peer": peer, "url": app.start(), "gateway": gateway}
        finally:
            gateway.shutdown()
            app.stop()
            gateway.node.shutdown("test over")
            peer.shutdown("test over")


def test_publish_services_parameters_and_reconnect(served: dict[str, Any], browser_page: Any) -> None:
    peer = served["peer"]
    page = browser_page
    page.goto(served["url"])
    counter = peer.publisher("/counter", get_message_class("std_msgs/Int32"), queue_size=10)
    heard: list[str] = []
    peer.subscriber(
        "/from_page", get_message_class("std_msgs/String"), lambda m: heard.append(m.data), queue_size=10
    )
    peer.service(
        "/set_flag",
        get_service_class("std_srvs/SetBool"),
        lambda req: get_service_class("std_srvs/SetBool")._response_class(
            success=req.data, message="flag is set"
        ),
    )
    peer.set_param("/robot/speed", 0.5)
    assert page.evaluate(SETUP)

    # subscribing: plain objects, in order
    def count_seen(n: int) -> bool:
        counter.publish(get_message_class("std_msgs/Int32")(data=n))
        return n in page.evaluate("got")

    wait_until(lambda: count_seen(7), what="the page to receive /counter")
    # publishing a type no channel advertised yet (the definition comes from /api/msgdef)
    page.evaluate("window.pub = ros.advertise('/from_page', 'std_msgs/String'); pub.ready")

    def heard_page() -> bool:
        page.evaluate("pub.publish({data: 'hello from the browser'})")
        return "hello from the browser" in heard

    wait_until(heard_page, what="the peer to hear the page")
    # services: ROS 1 bytes both ways
    resp = page.evaluate("ros.callService('/set_flag', {data: true})")
    assert resp == {"success": True, "message": "flag is set"}
    failure = page.evaluate("ros.callService('/nope', {}).then(() => 'ok', (e) => e.message)")
    assert failure == "service /nope is not advertised"
    # parameters
    assert page.evaluate("ros.getParameters(['/robot/speed'])") == {"/robot/speed": 0.5}
    page.evaluate("ros.setParameters({'/robot/name': 'puzzlebot'})")
    assert peer.get_param("/robot/name") == "puzzlebot"
    # reconnection: the socket drops, the client comes back and its subscription with it
    page.evaluate("ros.ws.close(); got.length = 0")
    wait_until(lambda: page.evaluate("closes === 1 && ros.connected"), what="the reconnection")
    wait_until(lambda: count_seen(42), what="/counter again after reconnecting")
