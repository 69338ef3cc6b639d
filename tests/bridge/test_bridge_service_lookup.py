"""The gateway's service calls ask the master once per provider, not once per call, and still follow a
provider that goes away or comes back with another type (``bridge.graph.Services``)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.bridge.graph import Services
from ninjemys.errors import ServiceError
from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node

AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")
Trigger = get_service_class("std_srvs/Trigger")


@pytest.fixture
def services(master_uri: str) -> Iterator[tuple[Services, list[str]]]:
    """The gateway's Services on their own node, and the list of services it looked up on the master."""
    gw_node = Node("gateway_side", anonymous=True, master_uri=master_uri)
    lookups: list[str] = []
    real_lookup = gw_node.master.lookup_service

    def counting_lookup(service: str) -> Any:
        lookups.append(service)
        return real_lookup(service)

    gw_node.master.lookup_service = counting_lookup  # type: ignore[method-assign]
    calls = Services(gw_node)
    yield calls, lookups
    calls.close()
    gw_node.shutdown("test over")


def add(calls: Services, a: int, b: int) -> Any:
    """A rosbridge-style call: no type given (roslibjs and roslibpy send none), fields from a dict."""

    def build(request_class: Any) -> Any:
        request = request_class()
        for name, value in (("a", a), ("b", b)):
            setattr(request, name, value)
        return request

    return calls.call("/lookup_add", None, build)


def test_calls_without_a_type_ask_the_master_once_per_provider(
    services: tuple[Services, list[str]], master_uri: str
) -> None:
    calls, lookups = services
    provider = Node("lookup_provider", anonymous=True, master_uri=master_uri)
    try:
        provider.service("/lookup_add", AddTwoInts, lambda r: r.a + r.b)
        assert [add(calls, i, 1).sum for i in range(30)] == [i + 1 for i in range(30)]
        # the type probe's lookup and the persistent connection's own: not one per call
        assert len(lookups) <= 2, lookups
        raw = calls.call_raw("/lookup_add", AddTwoInts._request_class(a=2, b=3).serialize_to_bytes())
        assert AddTwoInts._response_class.deserialize_from(raw).sum == 5
        assert len(lookups) <= 3, lookups
    finally:
        provider.shutdown("test over")


def test_a_provider_that_restarts_with_another_type_is_followed(
    services: tuple[Services, list[str]], master_uri: str
) -> None:
    calls, _ = services
    first = Node("lookup_first", anonymous=True, master_uri=master_uri)
    first.service("/lookup_add", AddTwoInts, lambda r: r.a + r.b)
    try:
        assert add(calls, 2, 2).sum == 4
    finally:
        first.shutdown("replaced")
    # gone: the next call says so (the master is asked again once the connection fails)
    with pytest.raises(ServiceError, match="does not exist"):
        add(calls, 1, 1)
    second = Node("lookup_second", anonymous=True, master_uri=master_uri)
    try:
        second.service("/lookup_add", AddTwoInts, lambda r: r.a * r.b)
        assert add(calls, 3, 4).sum == 12  # a new provider of the same type at a new address
    finally:
        second.shutdown("replaced")
    third = Node("lookup_third", anonymous=True, master_uri=master_uri)
    try:
        third.service("/lookup_add", Trigger, lambda r: (True, "now a trigger"))
        reply = calls.call("/lookup_add", None, lambda request_class: request_class())
        assert (reply.success, reply.message) == (True, "now a trigger")  # probed again: its new type
    finally:
        third.shutdown("test over")


def test_a_service_unregistered_by_a_live_node_is_gone_for_the_gateway_too(
    services: tuple[Services, list[str]], master_uri: str
) -> None:
    """The persistent connection is no licence to call a service its node withdrew."""
    calls, _ = services
    provider = Node("lookup_withdraws", anonymous=True, master_uri=master_uri)
    try:
        server = provider.service("/lookup_add", AddTwoInts, lambda r: r.a + r.b)
        assert add(calls, 1, 2).sum == 3
        server.shutdown()
        with pytest.raises(ServiceError, match="does not exist"):
            add(calls, 1, 2)
    finally:
        provider.shutdown("test over")


def test_the_gateway_starts_without_probing_services_and_advertises_them_next(
    master_uri: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """start() returns with the graph and topics known; the services' types (a lookup and a connection
    per service, two services per node) come from the poller's first round, not from the caller's."""
    from ninjemys.bridge.server import Gateway, GatewayOptions
    from ninjemys.testing import free_port, wait_until

    provider = Node("lookup_start_provider", master_uri=master_uri)
    provider.service("/lookup_add", AddTwoInts, lambda r: r.a + r.b)
    probed_on: list[str] = []
    real_type = Services.service_type

    def recording_type(self: Services, service: str) -> str:
        import threading

        probed_on.append(threading.current_thread().name)
        return real_type(self, service)

    monkeypatch.setattr(Services, "service_type", recording_type)
    gateway = Gateway(GatewayOptions(port=free_port(), update_period=0.2))
    try:
        gateway.start()
        # the first refresh (in start) knew the graph: the provider's node is in it
        assert "/lookup_start_provider" in gateway.catalog.node_names()
        entry = wait_until(
            lambda: next((s for s in gateway.catalog.services.values() if s["name"] == "/lookup_add"), None),
            20.0,
            "/lookup_add advertised",
        )
        assert entry["type"] == "rospy_tutorials/AddTwoInts"
        assert probed_on and set(probed_on) == {"gateway-graph"}, probed_on
    finally:
        gateway.shutdown()
        provider.shutdown("test over")
