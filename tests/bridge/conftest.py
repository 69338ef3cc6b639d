"""Fixtures for the gateway: an in-process master, the gateway on a free port, a helper node."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import free_port


@pytest.fixture
def master_uri(monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    with MasterThread() as uri:
        monkeypatch.setenv("ROS_MASTER_URI", uri)
        yield uri


@pytest.fixture
def make_gateway(master_uri: str) -> Iterator[Callable[..., Gateway]]:
    """``make_gateway(**options)`` starts a gateway on a free port (shut down after the test)."""
    started: list[Gateway] = []

    def make(**options: object) -> Gateway:
        opts = GatewayOptions(port=free_port(), update_period=0.2, **options)  # type: ignore[arg-type]
        gateway = Gateway(opts)
        gateway.run_in_thread()
        started.append(gateway)
        return gateway

    yield make
    for gateway in started:
        gateway.shutdown()


@pytest.fixture
def gateway(make_gateway: Callable[..., Gateway]) -> Gateway:
    return make_gateway()


@pytest.fixture
def node(master_uri: str) -> Iterator[Node]:
    n = Node("bridge_test_peer", anonymous=True, master_uri=master_uri)
    yield n
    n.shutdown("test over")
