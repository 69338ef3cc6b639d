"""Services between ninjemys and real ROS 1 (rospy client/server, roscpp server), over both masters."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

sys.path[:0] = [str(Path(__file__).parent), str(Path(__file__).parents[1] / "node")]

from node_harness import MasterProcess  # noqa: E402
from node_msgs import Trigger  # noqa: E402
from ros1_peers import ROSPY_CLIENT, ROSPY_SERVICE, roscpp, rospy  # noqa: E402

from ninjemys import testing  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import NodeProcess  # noqa: E402

pytestmark = pytest.mark.ros1


@pytest.fixture(params=["ninjemys", "ros1"], ids=["our-roscore", "real-rosmaster"])
def master(request: pytest.FixtureRequest) -> Iterator[MasterProcess]:
    m = MasterProcess(testing.free_port(), kind=request.param)
    m.start()
    try:
        yield m
    finally:
        m.kill()


@pytest.fixture
def node(master: MasterProcess) -> Iterator[Node]:
    n = Node("ninjemys_node", master_uri=master.uri)
    try:
        yield n
    finally:
        n.shutdown("test over")


@pytest.fixture
def peers() -> Iterator[list[NodeProcess]]:
    started: list[NodeProcess] = []
    try:
        yield started
    finally:
        for child in started:
            child.kill()


@pytest.mark.parametrize("mode", ["persistent", "fresh"])
def test_rospy_client_calls_our_service(master, node, peers, mode: str) -> None:
    calls: list[object] = []

    def handle(req):
        calls.append(req)
        return Trigger._response_class(True, f"ninjemys answer {len(calls)}")

    def failing(req):
        raise RuntimeError("this service always fails")

    node.service("ninjemys_trigger", Trigger, handle)
    node.service("ninjemys_failing", Trigger, failing)
    child = rospy(ROSPY_CLIENT, master.uri, mode)
    peers.append(child)
    assert child.proc.wait(30) == 0, child.describe()
    assert child.out[:3] == [f"response True ninjemys answer {i}" for i in (1, 2, 3)]
    assert child.out[3].startswith("error ") and "this service always fails" in child.out[3]


@pytest.mark.parametrize("impl", ["rospy", "roscpp"])
@pytest.mark.parametrize("persistent", [False, True], ids=["fresh", "persistent"])
def test_our_proxy_calls_ros1_service(master, node, peers, impl: str, persistent: bool) -> None:
    child = rospy(ROSPY_SERVICE, master.uri) if impl == "rospy" else roscpp(master.uri, "service")
    peers.append(child)
    assert child.wait_for(lambda line: line == "ready", timeout=30), child.describe()
    name = "/rospy_trigger" if impl == "rospy" else "/cpp_trigger"
    node.wait_for_service(name, timeout=15)
    proxy = node.service_proxy(name, Trigger, persistent=persistent)
    for _ in range(3):
        response = proxy()
        assert response.success is True
        assert response.message == f"{impl} says hi"


def test_roscpp_client_calls_our_service(master, node, peers) -> None:
    count = [0]

    def handle(req):
        count[0] += 1
        return Trigger._response_class(True, f"ninjemys answer {count[0]}")

    def failing(req):
        raise RuntimeError("this service always fails")

    node.service("ninjemys_trigger", Trigger, handle)
    node.service("ninjemys_failing", Trigger, failing)
    child = roscpp(master.uri, "client")
    peers.append(child)
    assert child.proc.wait(30) == 0, child.describe()
    assert child.out == [f"response True ninjemys answer {i}" for i in (1, 2, 3)] + ["failing call failed"]
