"""The node runtime's own event loop (ninjemys.net.loop): timers, tasks, cancellation, deadlines,
sockets, cross-thread hand-offs and shutdown, each checked against the asyncio behaviour it mirrors."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.net import loop as nloop
from ninjemys.net.loop import CancelledError, Loop


@pytest.fixture
def loop() -> Iterator[Loop]:
    lp = Loop()
    try:
        yield lp
    finally:
        if not lp.is_closed():
            lp.shutdown_tasks(grace=0.5)
            lp.close()


@pytest.fixture
def threaded() -> Iterator[Loop]:
    """A loop running on its own thread, as the node runtime runs it."""
    lp = Loop()
    thread = threading.Thread(target=lp.run_forever, daemon=True)
    thread.start()
    try:
        yield lp
    finally:
        lp.call_soon_threadsafe(lp.stop)
        thread.join(5)
        assert not thread.is_alive()
        lp.shutdown_tasks(grace=0.5)
        lp.close()


def test_callbacks_run_in_order_and_timers_by_due_time(loop: Loop) -> None:
    seen: list[str] = []
    loop.call_later(0.03, seen.append, "late")
    loop.call_later(0.01, seen.append, "early")
    loop.call_soon(seen.append, "soon1")
    loop.call_soon(seen.append, "soon2")
    loop.call_later(0.05, loop.stop)
    loop.run_forever()
    assert seen == ["soon1", "soon2", "early", "late"]


def test_cancelled_timer_never_runs_and_heap_is_compacted(loop: Loop) -> None:
    seen: list[int] = []
    handles = [loop.call_later(10 + i, seen.append, i) for i in range(300)]
    for handle in handles:
        handle.cancel()
    assert len(loop._timers) < 300  # rebuilt once most entries were cancelled
    kept = loop.call_later(0.01, seen.append, -1)
    loop.call_later(0.02, loop.stop)
    loop.run_forever()
    assert seen == [-1] and not kept.cancelled()


def test_a_failing_callback_is_logged_and_the_loop_keeps_running(
    loop: Loop, caplog: pytest.LogCaptureFixture
) -> None:
    seen: list[str] = []

    def boom() -> None:
        raise ValueError("callback bug")

    loop.call_soon(boom)
    loop.call_soon(seen.append, "after")
    loop.call_later(0.01, loop.stop)
    loop.run_forever()
    assert seen == ["after"]
    assert "callback bug" in caplog.text


def test_task_result_and_exception(loop: Loop) -> None:
    async def add(a: int, b: int) -> int:
        await nloop.sleep(0.001)
        return a + b

    async def fail() -> None:
        await nloop.sleep(0)
        raise KeyError("missing")

    assert loop.run_until_complete(add(2, 3)) == 5
    with pytest.raises(KeyError, match="missing"):
        loop.run_until_complete(fail())


def test_cancel_throws_at_the_await_and_finally_runs(loop: Loop) -> None:
    events: list[str] = []

    async def worker() -> None:
        try:
            await nloop.sleep(10)
        except CancelledError:
            events.append("cancelled")
            raise
        finally:
            events.append("finally")

    async def main() -> bool:
        task = loop.create_task(worker())
        await nloop.sleep(0.01)
        task.cancel()
        try:
            await task
        except CancelledError:
            return task.cancelled()
        return False

    assert loop.run_until_complete(main()) is True
    assert events == ["cancelled", "finally"]


def test_cancel_before_first_step_never_runs_the_body(loop: Loop) -> None:
    ran: list[bool] = []

    async def body() -> None:
        ran.append(True)

    task = loop.create_task(body())
    task.cancel()
    loop.call_later(0.01, loop.stop)
    loop.run_forever()
    assert task.cancelled() and ran == []


def test_timeout_raises_builtin_timeout_error_and_cleans_up(loop: Loop) -> None:
    async def slow() -> str:
        async with nloop.timeout(0.02):
            await nloop.sleep(5)
        return "not reached"

    async def fast() -> str:
        async with nloop.timeout(5):
            await nloop.sleep(0.001)
        return "ok"

    start = time.monotonic()
    with pytest.raises(TimeoutError):
        loop.run_until_complete(slow())
    assert time.monotonic() - start < 2.0
    assert loop.run_until_complete(fast()) == "ok"
    assert all(t.cancelled() for t in loop._timers)  # the 5 s deadline did not stay armed


def test_outside_cancellation_is_not_turned_into_a_timeout(loop: Loop) -> None:
    async def guarded() -> None:
        async with nloop.timeout(5):
            await nloop.sleep(5)

    async def main() -> str:
        task = loop.create_task(guarded())
        await nloop.sleep(0.01)
        task.cancel()
        try:
            await task
        except CancelledError:
            return "cancelled"
        except TimeoutError:
            return "timeout"
        return "finished"

    assert loop.run_until_complete(main()) == "cancelled"


def test_cross_thread_handoffs(threaded: Loop) -> None:
    async def double(x: int) -> int:
        await nloop.sleep(0.001)
        return 2 * x

    futures = [threaded.run_coroutine_threadsafe(double(i)) for i in range(50)]
    assert [f.result(5) for f in futures] == [2 * i for i in range(50)]

    async def broken() -> None:
        raise ValueError("from the loop")

    with pytest.raises(ValueError, match="from the loop"):
        threaded.run_coroutine_threadsafe(broken()).result(5)

    seen = threading.Event()
    workers = [threading.Thread(target=threaded.call_soon_threadsafe, args=(seen.set,)) for _ in range(4)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    assert seen.wait(5)


def test_waiting_from_another_thread_times_out_and_cancel_reaches_the_task(threaded: Loop) -> None:
    cancelled = threading.Event()

    async def forever() -> None:
        try:
            await nloop.sleep(60)
        except CancelledError:
            cancelled.set()
            raise

    future = threaded.run_coroutine_threadsafe(forever())
    with pytest.raises(TimeoutError):
        future.result(0.05)
    future.cancel()
    assert cancelled.wait(5)
    with pytest.raises(CancelledError):
        future.result(5)


def test_closed_loop_refuses_work(loop: Loop) -> None:
    loop.close()
    with pytest.raises(RuntimeError):
        loop.call_soon_threadsafe(print)

    async def nothing() -> None:
        pass

    coro = nothing()
    with pytest.raises(RuntimeError):
        loop.run_coroutine_threadsafe(coro)


def test_shutdown_with_pending_tasks_runs_their_cleanup(loop: Loop) -> None:
    cleaned: list[int] = []

    async def pending(i: int) -> None:
        try:
            await nloop.sleep(60)
        finally:
            cleaned.append(i)

    tasks = [loop.create_task(pending(i)) for i in range(5)]
    loop.call_later(0.01, loop.stop)
    loop.run_forever()
    start = time.monotonic()
    loop.shutdown_tasks(grace=1.0)
    assert sorted(cleaned) == [0, 1, 2, 3, 4]
    assert all(t.cancelled() for t in tasks)
    assert time.monotonic() - start < 1.0
    loop.close()


def test_socket_calls_and_a_dead_peer(loop: Loop) -> None:
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(4)
    listener.setblocking(False)
    port = listener.getsockname()[1]

    async def exchange() -> tuple[bytes, int, bytes]:
        client = socket.socket()
        client.setblocking(False)
        accept = loop.create_task(loop.sock_accept(listener))
        await loop.sock_connect(client, ("localhost", port))  # a host name: resolved off the loop
        server, _ = await accept
        payload = b"x" * 3_000_000  # more than the socket buffers: sendall must wait for writability
        sender = loop.create_task(loop.sock_sendall(client, payload))
        got = bytearray()
        buf = bytearray(65536)
        while len(got) < len(payload):
            n = await loop.sock_recv_into(server, buf)
            got += buf[:n]
        await sender
        client.close()
        eof = await loop.sock_recv(server, 10)  # the peer went away: an empty read, not a hang
        server.close()
        return bytes(got[:3]), len(got), eof

    try:
        head, size, eof = loop.run_until_complete(exchange())
    finally:
        listener.close()
    assert (head, size, eof) == (b"xxx", 3_000_000, b"")

    async def refused() -> None:
        sock = socket.socket()
        sock.setblocking(False)
        try:
            await loop.sock_connect(sock, ("127.0.0.1", port))  # the listener is closed now
        finally:
            sock.close()

    with pytest.raises(ConnectionRefusedError):
        loop.run_until_complete(refused())
    assert len(loop._selector.get_map()) == 1  # only the wake-up pipe: every watch was removed


def test_cancelled_socket_wait_unregisters_the_fd(loop: Loop) -> None:
    a, b = socket.socketpair()
    a.setblocking(False)

    async def main() -> None:
        task = loop.create_task(loop.sock_recv(a, 10))
        await nloop.sleep(0.01)
        assert a.fileno() in loop._selector.get_map()
        task.cancel()
        with pytest.raises(CancelledError):
            await task

    try:
        loop.run_until_complete(main())
        assert a.fileno() not in loop._selector.get_map()
    finally:
        a.close()
        b.close()


def test_reader_and_writer_share_an_fd(loop: Loop) -> None:
    a, b = socket.socketpair()
    events: list[str] = []

    def on_read() -> None:
        events.append("read")
        a.recv(100)
        loop.remove_reader(a)

    def on_write() -> None:
        events.append("write")
        loop.remove_writer(a.fileno())

    try:
        loop.add_reader(a, on_read)
        loop.add_writer(a, on_write)
        b.send(b"hi")
        loop.call_later(0.05, loop.stop)
        loop.run_forever()
        assert sorted(events) == ["read", "write"]
        assert not loop.remove_reader(a) and not loop.remove_writer(a)
    finally:
        a.close()
        b.close()


def test_timeout_and_sleep_follow_asyncio_when_it_runs() -> None:
    import asyncio

    async def main() -> Any:
        assert nloop.get_running_loop() is asyncio.get_running_loop()
        await nloop.sleep(0.001)
        with pytest.raises(TimeoutError):
            async with nloop.timeout(0.01):
                await asyncio.sleep(5)
        return "ok"

    assert asyncio.run(main()) == "ok"


def test_no_running_loop_is_an_error() -> None:
    result: list[BaseException] = []

    def probe() -> None:
        try:
            nloop.get_running_loop()
        except RuntimeError as exc:
            result.append(exc)

    thread = threading.Thread(target=probe)
    thread.start()
    thread.join()
    # asyncio may be imported by the test session, but no loop runs on that thread
    assert len(result) == 1
