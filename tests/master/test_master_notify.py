"""publisherUpdate fan-out: asynchronous, per node, with deadlines (the ros_comm#1555 scenario)."""

from __future__ import annotations

import asyncio
import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.master.client import MasterClient
from ninjemys.master.core import MasterThread
from ninjemys.master.notify import Notifier
from ninjemys.net.xmlrpc_server import XmlRpcServer


class Slave:
    """A minimal node XML-RPC server that records publisherUpdate / paramUpdate calls."""

    def __init__(self) -> None:
        self.updates: list[tuple[str, Any]] = []
        self.event = threading.Event()

    def publisherUpdate(self, caller_id: str, topic: str, publishers: list[str]) -> list[Any]:  # noqa: N802
        self.updates.append((topic, publishers))
        self.event.set()
        return [1, "", 0]

    def paramUpdate(self, caller_id: str, key: str, value: Any) -> list[Any]:  # noqa: N802
        self.updates.append((key, value))
        self.event.set()
        return [1, "", 0]


@pytest.fixture
def loop() -> Iterator[asyncio.AbstractEventLoop]:
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    try:
        yield loop
    finally:
        loop.call_soon_threadsafe(loop.stop)
        thread.join(5)
        loop.close()


def serve(loop: asyncio.AbstractEventLoop, handler: object) -> XmlRpcServer:
    server = XmlRpcServer(handler, "127.0.0.1", 0, advertise="127.0.0.1")
    asyncio.run_coroutine_threadsafe(server.start(), loop).result(5)
    return server


@pytest.fixture
def black_holes() -> Iterator[list[str]]:
    """Listening sockets that accept connections and never answer."""
    socks = []
    for _ in range(5):
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        s.listen(100)
        socks.append(s)
    try:
        yield [f"http://127.0.0.1:{s.getsockname()[1]}/" for s in socks]
    finally:
        for s in socks:
            s.close()


def test_hostile_subscribers_do_not_delay_anyone(
    loop: asyncio.AbstractEventLoop, black_holes: list[str]
) -> None:
    good = Slave()
    server = serve(loop, good)
    try:
        with MasterThread() as uri:
            master = MasterClient(uri, "/x")
            for i, api in enumerate(black_holes):  # more hostile nodes than rosmaster has workers
                MasterClient(uri, f"/hostile{i}").register_subscriber("/busy", "std_msgs/String", api)
            MasterClient(uri, "/pub").register_publisher("/busy", "std_msgs/String", "http://127.0.0.1:1/")
            start = time.monotonic()
            MasterClient(uri, "/good").register_subscriber("/other", "std_msgs/String", server.uri)
            MasterClient(uri, "/talker").register_publisher(
                "/other", "std_msgs/String", "http://127.0.0.1:2/"
            )
            assert good.event.wait(5), "publisherUpdate to a healthy node was held up"
            assert time.monotonic() - start < 3
            assert good.updates == [("/other", ["http://127.0.0.1:2/"])]
            assert master.get_pid() > 0
    finally:
        loop.call_soon_threadsafe(server.close)


def test_updates_for_one_topic_coalesce_and_stay_ordered(loop: asyncio.AbstractEventLoop) -> None:
    slave = Slave()
    server = serve(loop, slave)

    async def burst() -> None:
        notifier = Notifier(timeout=2)
        for i in range(50):
            notifier.publisher_update(server.uri, "/t", [f"http://p{j}/" for j in range(i + 1)])
        notifier.param_update(server.uri, "/k/", 1)
        await notifier.drain(5)

    try:
        asyncio.run_coroutine_threadsafe(burst(), loop).result(10)
        assert len(slave.updates) < 50  # coalesced
        assert slave.updates[-2] == ("/t", [f"http://p{j}/" for j in range(50)])  # the latest list wins
        assert slave.updates[-1] == ("/k/", 1)
    finally:
        loop.call_soon_threadsafe(server.close)


def test_deadline_bounds_a_silent_node(black_holes: list[str]) -> None:
    async def run() -> float:
        notifier = Notifier(timeout=0.3)
        start = time.monotonic()
        notifier.publisher_update(black_holes[0], "/t", [])
        notifier.shutdown_node(black_holes[0], "bye")
        await notifier.drain(5)
        return time.monotonic() - start

    elapsed = asyncio.run(run())
    assert 0.5 <= elapsed < 3


def test_refused_node_is_dead_until_it_registers_again() -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        closed = f"http://127.0.0.1:{s.getsockname()[1]}/"  # bound, not listening: refuses

        async def run() -> tuple[bool, int, bool, int]:
            notifier = Notifier(timeout=2)
            notifier.publisher_update(closed, "/t", [])
            await notifier.drain(5)
            dead = notifier.is_dead(closed)
            notifier.publisher_update(closed, "/t", ["x"])
            dropped = notifier.pending()
            notifier.revive(closed)
            notifier.publisher_update(closed, "/t", ["y"])
            queued = notifier.pending()
            notifier.close()
            return dead, dropped, notifier.is_dead(closed), queued

        dead, dropped, still_dead, queued = asyncio.run(run())
    assert dead and dropped == 0
    assert not still_dead and queued > 0
