"""A small selector event loop that runs coroutines: the node runtime's loop, without importing asyncio.

Why: ``import asyncio`` costs more than everything else a node process imports (its base_events
pulls ssl, subprocess, concurrent.futures, inspect...), roughly doubling ``import rospy``. A node's
I/O thread needs a tiny part of it: callbacks soon/later/from other threads, fd readiness, tasks
running ``async def`` coroutines with cancellation, non-blocking socket calls, a deadline and a
sleep. That subset is here, with asyncio's names and semantics (``call_soon``, ``call_later``,
``add_reader``, ``create_task``, ``sock_recv_into``, ``sock_sendall``, ``sock_connect``,
``sock_accept``, ``getaddrinfo``...), so code written against it also runs on an asyncio loop: the
XML-RPC server and client in :mod:`ninjemys.net` serve the node (this loop) and the master and
web tools (asyncio) alike. Code that must work on both gets its loop from :func:`get_running_loop`
and uses :func:`timeout` and :func:`sleep` from here, which pick the running loop's flavour.

What it deliberately lacks: subprocesses, signals, SSL, streams, executors; a task awaits only
futures of its own loop.
"""

from __future__ import annotations

import heapq
import logging
import os
import selectors
import socket
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Coroutine, Generator

from ninjemys.net.addresses import lookup_host

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_log = logging.getLogger(__name__)

_PENDING, _DONE, _CANCELLED = 0, 1, 2
_current = threading.local()
#: Rebuild the timer heap when more than this many (and more than half) of its entries are cancelled.
_MAX_CANCELLED_TIMERS = 100


class CancelledError(BaseException):
    """A task or future was cancelled (a BaseException, as asyncio's, so ``except Exception`` lets it by)."""


class InvalidStateError(Exception):
    """A future's result was asked before it was set, or set twice."""


def get_running_loop() -> Any:
    """The loop running on this thread: a :class:`Loop`, else asyncio's running loop.

    asyncio is consulted only if something already imported it, so a node process never does.
    """
    loop = getattr(_current, "loop", None)
    if loop is not None:
        return loop
    aio = sys.modules.get("asyncio")
    if aio is not None:
        return aio.get_running_loop()
    raise RuntimeError("no running event loop")


def timeout(delay: float | None) -> Any:
    """``async with timeout(s):`` raises the builtin ``TimeoutError`` after ``s`` seconds, on either loop."""
    if isinstance(getattr(_current, "loop", None), Loop):
        return _Timeout(delay)
    import asyncio  # only reached inside a running asyncio loop, so already imported

    return asyncio.timeout(delay)


async def sleep(delay: float) -> None:
    """Suspend the calling task for ``delay`` seconds on whichever loop runs it."""
    loop = getattr(_current, "loop", None)
    if loop is None:
        import asyncio

        await asyncio.sleep(delay)
        return
    future = loop.create_future()
    handle = loop.call_later(delay, _set_result_unless_done, future, None)
    try:
        await future
    finally:
        handle.cancel()


def _set_result_unless_done(future: Future, value: Any) -> None:
    if not future.done():
        future.set_result(value)


class Handle:
    """A callback scheduled on the loop; :meth:`cancel` keeps it from running."""

    __slots__ = ("_callback", "_args", "_cancelled")

    def __init__(self, callback: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self._callback = callback
        self._args = args
        self._cancelled = False

    def cancel(self) -> None:
        self._cancelled = True

    def cancelled(self) -> bool:
        return self._cancelled

    def _run(self) -> None:
        try:
            self._callback(*self._args)
        except (SystemExit, KeyboardInterrupt):
            raise
        except BaseException:
            _log.exception("exception in loop callback %r", self._callback)


class TimerHandle(Handle):
    """A callback due at :attr:`when` (loop time, ``time.monotonic``)."""

    __slots__ = ("when", "_loop")

    def __init__(self, when: float, callback: Callable[..., Any], args: tuple[Any, ...], loop: Loop) -> None:
        super().__init__(callback, args)
        self.when = when
        self._loop = loop

    def __lt__(self, other: TimerHandle) -> bool:
        return self.when < other.when

    def cancel(self) -> None:
        if not self._cancelled:
            self._cancelled = True
            self._loop._timer_cancelled()


class Future:
    """A result that will exist later, on one loop; ``await`` it from a task of that loop."""

    _asyncio_future_blocking = False

    def __init__(self, loop: Loop) -> None:
        self._loop = loop
        self._state = _PENDING
        self._result: Any = None
        self._exception: BaseException | None = None
        self._callbacks: list[Callable[[Future], Any]] = []
        self._retrieved = False

    def get_loop(self) -> Loop:
        return self._loop

    def done(self) -> bool:
        return self._state != _PENDING

    def cancelled(self) -> bool:
        return self._state == _CANCELLED

    def cancel(self, msg: str | None = None) -> bool:
        if self._state != _PENDING:
            return False
        self._state = _CANCELLED
        self._exception = CancelledError(msg) if msg else CancelledError()
        self._schedule_callbacks()
        return True

    def result(self) -> Any:
        if self._state == _PENDING:
            raise InvalidStateError("result is not set")
        self._retrieved = True
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        if self._state == _PENDING:
            raise InvalidStateError("exception is not set")
        if self._state == _CANCELLED:
            assert self._exception is not None
            raise self._exception
        self._retrieved = True
        return self._exception

    def set_result(self, value: Any) -> None:
        if self._state != _PENDING:
            raise InvalidStateError("future already done")
        self._result = value
        self._state = _DONE
        self._schedule_callbacks()

    def set_exception(self, exc: BaseException) -> None:
        if self._state != _PENDING:
            raise InvalidStateError("future already done")
        if isinstance(exc, type):
            exc = exc()
        self._exception = exc
        self._state = _DONE
        self._schedule_callbacks()

    def add_done_callback(self, fn: Callable[[Any], Any]) -> None:
        """Call ``fn(future)`` on the loop once done (soon, if it already is)."""
        if self._state != _PENDING:
            self._loop.call_soon(fn, self)
        else:
            self._callbacks.append(fn)

    def remove_done_callback(self, fn: Callable[[Any], Any]) -> int:
        before = len(self._callbacks)
        self._callbacks = [cb for cb in self._callbacks if cb != fn]
        return before - len(self._callbacks)

    def _schedule_callbacks(self) -> None:
        callbacks, self._callbacks = self._callbacks, []
        for fn in callbacks:
            self._loop.call_soon(fn, self)

    def __await__(self) -> Generator[Any, None, Any]:
        if self._state == _PENDING:
            self._asyncio_future_blocking = True
            yield self
        if self._state == _PENDING:
            raise RuntimeError("await wasn't used with future")
        return self.result()

    __iter__ = __await__

    def __del__(self) -> None:
        if self._state == _DONE and self._exception is not None and not self._retrieved:
            _log.error(
                "%s exception was never retrieved: %s: %s",
                type(self).__name__,
                type(self._exception).__name__,
                self._exception,
            )


class Task(Future):
    """Runs a coroutine on the loop, step by step, each time the future it awaits is done."""

    def __init__(self, coro: Coroutine[Any, Any, Any], loop: Loop, name: str | None = None) -> None:
        super().__init__(loop)
        self._coro = coro
        self._name = name or getattr(coro, "__qualname__", "task")
        self._waiter: Future | None = None
        self._must_cancel = False
        loop._tasks.add(self)
        loop.call_soon(self._step)

    def __repr__(self) -> str:
        state = ("pending", "done", "cancelled")[self._state]
        return f"<Task {self._name} {state}>"

    def get_coro(self) -> Coroutine[Any, Any, Any]:
        return self._coro

    def cancel(self, msg: str | None = None) -> bool:
        """Throw ``CancelledError`` into the coroutine at its current ``await`` (it may catch it)."""
        if self._state != _PENDING:
            return False
        if self._waiter is not None and self._waiter.cancel():
            return True
        self._must_cancel = True
        return True

    def _step(self, exc: BaseException | None = None) -> None:
        if self._state != _PENDING:
            return
        if self._must_cancel:
            self._must_cancel = False
            if not isinstance(exc, CancelledError):
                exc = CancelledError()
        self._waiter = None
        loop = self._loop
        previous, loop._current_task = loop._current_task, self
        try:
            if exc is None:
                awaited = self._coro.send(None)
            else:
                awaited = self._coro.throw(exc)
        except StopIteration as stop:
            self._finish()
            super().set_result(stop.value)
        except CancelledError:
            self._finish()
            super().cancel()
        except (KeyboardInterrupt, SystemExit) as error:
            self._finish()
            super().set_exception(error)
            raise
        except BaseException as error:
            self._finish()
            super().set_exception(error)
        else:
            self._wait_on(awaited)
        finally:
            loop._current_task = previous

    def _wait_on(self, awaited: Any) -> None:
        if awaited is None:  # a bare yield: let others run, then continue
            self._loop.call_soon(self._step)
            return
        if not isinstance(awaited, Future) or awaited._loop is not self._loop:
            error = RuntimeError(f"task {self._name} awaited {awaited!r}, not a future of its own loop")
            self._loop.call_soon(self._step, error)
            return
        awaited._asyncio_future_blocking = False
        self._waiter = awaited
        awaited.add_done_callback(self._wakeup)
        if self._must_cancel and awaited.cancel():
            self._must_cancel = False

    def _wakeup(self, future: Future) -> None:
        try:
            future.result()
        except BaseException as exc:
            self._step(exc)
        else:
            self._step()

    def _finish(self) -> None:
        self._loop._tasks.discard(self)


class ThreadFuture:
    """The result of a coroutine run on the loop, waited for from another thread."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self._result: Any = None
        self._exception: BaseException | None = None
        self._cancel: Callable[[], None] | None = None

    def done(self) -> bool:
        return self._event.is_set()

    def result(self, timeout: float | None = None) -> Any:
        """The coroutine's value; raises its exception, or the builtin ``TimeoutError``."""
        if not self._event.wait(timeout):
            raise TimeoutError(f"no result within {timeout} s")
        if self._exception is not None:
            raise self._exception
        return self._result

    def cancel(self) -> None:
        """Cancel the task on the loop (from any thread)."""
        if self._cancel is not None and not self._event.is_set():
            self._cancel()

    def _copy(self, task: Future) -> None:
        if task.cancelled():
            self._exception = CancelledError()
        else:
            self._exception = task.exception()
            self._result = None if self._exception is not None else task.result()
        self._event.set()


class _Timeout:
    """``async with`` body cancelled after ``delay`` seconds; the cancellation becomes ``TimeoutError``."""

    __slots__ = ("_delay", "_handle", "_task", "_fired")

    def __init__(self, delay: float | None) -> None:
        self._delay = delay
        self._handle: TimerHandle | None = None
        self._task: Task | None = None
        self._fired = False

    async def __aenter__(self) -> _Timeout:
        loop = get_running_loop()
        self._task = loop.current_task()
        if self._task is None:
            raise RuntimeError("timeout() used outside a task")
        if self._delay is not None:
            self._handle = loop.call_later(max(0.0, self._delay), self._fire)
        return self

    def _fire(self) -> None:
        self._handle = None
        if self._task is not None and not self._task.done():
            self._fired = True
            self._task.cancel()

    async def __aexit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: Any
    ) -> None:
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None
        if self._fired and exc_type is CancelledError:
            raise TimeoutError(f"timed out after {self._delay:g} s") from None


class Loop:
    """One thread's event loop: ready callbacks, a timer heap and a selector, nothing more."""

    def __init__(self) -> None:
        self._selector = selectors.DefaultSelector()
        self._ready: deque[Handle] = deque()
        self._timers: list[TimerHandle] = []
        self._cancelled_timers = 0
        self._tasks: set[Task] = set()
        self._current_task: Task | None = None
        self._stopping = False
        self._closed = False
        self._thread_id: int | None = None
        self._wake_lock = threading.Lock()
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self._selector.register(self._wake_r, selectors.EVENT_READ, (Handle(self._drain_wakeups, ()), None))

    # -- scheduling ------------------------------------------------------------------------------

    def time(self) -> float:
        return time.monotonic()

    def call_soon(self, callback: Callable[..., Any], *args: Any) -> Handle:
        """Run ``callback(*args)`` on the next iteration (loop thread only)."""
        handle = Handle(callback, args)
        self._ready.append(handle)
        return handle

    def call_soon_threadsafe(self, callback: Callable[..., Any], *args: Any) -> Handle:
        """``call_soon`` from any thread; wakes the loop. ``RuntimeError`` once the loop is closed."""
        handle = Handle(callback, args)
        with self._wake_lock:  # close() must not free the pipe between the check and the write
            if self._closed:
                raise RuntimeError("the event loop is closed")
            self._ready.append(handle)
            self._wake()
        return handle

    def call_later(self, delay: float, callback: Callable[..., Any], *args: Any) -> TimerHandle:
        return self.call_at(time.monotonic() + delay, callback, *args)

    def call_at(self, when: float, callback: Callable[..., Any], *args: Any) -> TimerHandle:
        handle = TimerHandle(when, callback, args, self)
        heapq.heappush(self._timers, handle)
        return handle

    def create_future(self) -> Future:
        return Future(self)

    def create_task(self, coro: Coroutine[Any, Any, Any], *, name: str | None = None) -> Task:
        """Start running ``coro`` (on the next iteration); the task is kept until it finishes."""
        if self._closed:
            coro.close()
            raise RuntimeError("the event loop is closed")
        return Task(coro, self, name)

    def current_task(self) -> Task | None:
        return self._current_task

    def run_coroutine_threadsafe(self, coro: Coroutine[Any, Any, Any]) -> ThreadFuture:
        """Run ``coro`` on the loop from another thread; wait with ``.result(timeout)``."""
        result = ThreadFuture()
        box: list[Task] = []

        def start() -> None:
            task = self.create_task(coro)
            box.append(task)
            task.add_done_callback(result._copy)

        def cancel() -> None:
            if box:
                box[0].cancel()

        try:
            self.call_soon_threadsafe(start)
        except RuntimeError:
            coro.close()
            raise

        def cancel_soon() -> None:
            try:
                self.call_soon_threadsafe(cancel)
            except RuntimeError:
                pass  # the loop is gone, and the task with it

        result._cancel = cancel_soon
        return result

    def _timer_cancelled(self) -> None:
        self._cancelled_timers += 1
        if self._cancelled_timers > _MAX_CANCELLED_TIMERS and self._cancelled_timers * 2 > len(self._timers):
            self._timers = [t for t in self._timers if not t._cancelled]
            heapq.heapify(self._timers)
            self._cancelled_timers = 0

    # -- file descriptors ------------------------------------------------------------------------

    def add_reader(self, fd: Any, callback: Callable[..., Any], *args: Any) -> None:
        """Call ``callback(*args)`` whenever ``fd`` is readable (replaces an earlier reader)."""
        self._watch(_fileno(fd), 0, Handle(callback, args))

    def add_writer(self, fd: Any, callback: Callable[..., Any], *args: Any) -> None:
        """Call ``callback(*args)`` whenever ``fd`` is writable (replaces an earlier writer)."""
        self._watch(_fileno(fd), 1, Handle(callback, args))

    def remove_reader(self, fd: Any) -> bool:
        return self._unwatch(_fileno(fd), 0)

    def remove_writer(self, fd: Any) -> bool:
        return self._unwatch(_fileno(fd), 1)

    def _watch(self, fd: int, slot: int, handle: Handle) -> None:
        if self._closed:
            raise RuntimeError("the event loop is closed")
        try:
            key = self._selector.get_key(fd)
        except KeyError:
            pair = (handle, None) if slot == 0 else (None, handle)
            self._selector.register(fd, _events(pair), pair)
            return
        pair = (handle, key.data[1]) if slot == 0 else (key.data[0], handle)
        try:
            self._selector.modify(fd, _events(pair), pair)
        except OSError:  # the fd was closed and its number reused while still registered
            self._forget(fd)
            self._selector.register(fd, _events(pair), pair)

    def _unwatch(self, fd: int, slot: int) -> bool:
        if self._closed:
            return False
        try:
            key = self._selector.get_key(fd)
        except (KeyError, ValueError):
            return False
        if key.data[slot] is None:
            return False
        pair = (None, key.data[1]) if slot == 0 else (key.data[0], None)
        if pair == (None, None):
            self._forget(fd)
            return True
        try:
            self._selector.modify(fd, _events(pair), pair)
        except OSError:
            self._forget(fd)
        return True

    def _forget(self, fd: int) -> None:
        try:
            self._selector.unregister(fd)
        except (KeyError, ValueError, OSError):
            pass

    # -- sockets (non-blocking; each awaits readiness only when the call would block) -------------

    async def sock_recv(self, sock: socket.socket, n: int) -> bytes:
        try:
            return sock.recv(n)
        except (BlockingIOError, InterruptedError):
            pass
        return await self._when_ready(sock, 0, sock.recv, n)

    async def sock_recv_into(self, sock: socket.socket, buf: Any) -> int:
        try:
            return sock.recv_into(buf)
        except (BlockingIOError, InterruptedError):
            pass
        return await self._when_ready(sock, 0, sock.recv_into, buf)

    async def sock_sendall(self, sock: socket.socket, data: bytes | bytearray | memoryview) -> None:
        view = memoryview(data).cast("B")
        while view:
            try:
                sent = sock.send(view)
            except (BlockingIOError, InterruptedError):
                sent = await self._when_ready(sock, 1, sock.send, view)
            view = view[sent:]

    async def sock_accept(self, sock: socket.socket) -> tuple[socket.socket, Any]:
        try:
            conn, address = sock.accept()
        except (BlockingIOError, InterruptedError):
            conn, address = await self._when_ready(sock, 0, sock.accept)
        conn.setblocking(False)
        return conn, address

    async def sock_connect(self, sock: socket.socket, address: Any) -> None:
        """Connect a non-blocking socket; a host name is resolved first (off the loop)."""
        if sock.family in (socket.AF_INET, socket.AF_INET6) and not is_numeric_host(address[0]):
            infos = await self.getaddrinfo(address[0], address[1], family=sock.family, type=sock.type)
            if not infos:
                raise OSError(f"cannot resolve {address[0]}")
            address = infos[0][4]
        try:
            sock.connect(address)
            return
        except (BlockingIOError, InterruptedError):
            pass
        await self._when_ready(sock, 1, _connect_result, sock, address)

    async def getaddrinfo(
        self, host: Any, port: Any, *, family: int = 0, type: int = 0, proto: int = 0, flags: int = 0
    ) -> list[Any]:  # noqa: A002
        """``socket.getaddrinfo``; numeric hosts answered at once, names resolved on a helper thread."""
        if isinstance(host, str):
            host = lookup_host(host)
        if host is None or is_numeric_host(host):
            return socket.getaddrinfo(host, port, family, type, proto, flags)
        return await self.run_in_thread(socket.getaddrinfo, host, port, family, type, proto, flags)

    def run_in_thread(self, fn: Callable[..., Any], *args: Any) -> Future:
        """Run a blocking ``fn(*args)`` on a new daemon thread; a future of this loop gets its result."""
        future = self.create_future()

        def work() -> None:
            try:
                value = fn(*args)
            except BaseException as exc:
                self._deliver(future, None, exc)
            else:
                self._deliver(future, value, None)

        threading.Thread(target=work, name="ninjemys-io-helper", daemon=True).start()
        return future

    def _deliver(self, future: Future, value: Any, exc: BaseException | None) -> None:
        def settle() -> None:
            if future.done():
                return
            if exc is not None:
                future.set_exception(exc)
            else:
                future.set_result(value)

        try:
            self.call_soon_threadsafe(settle)
        except RuntimeError:
            pass  # the loop stopped meanwhile; nobody waits any more

    async def _when_ready(self, sock: socket.socket, slot: int, call: Callable[..., Any], *args: Any) -> Any:
        """Retry ``call(*args)`` each time ``sock`` is ready (read: slot 0, write: slot 1) until it
        stops raising BlockingIOError; the watch is removed however the wait ends."""
        fd = sock.fileno()
        if fd < 0:
            raise OSError(9, "socket is closed")
        future = self.create_future()
        self._watch(fd, slot, Handle(_retry_call, (future, call, args)))
        try:
            return await future
        finally:
            self._unwatch(fd, slot)

    # -- running ---------------------------------------------------------------------------------

    def is_running(self) -> bool:
        return self._thread_id is not None

    def is_closed(self) -> bool:
        return self._closed

    def stop(self) -> None:
        """Return from :meth:`run_forever` after the current iteration."""
        self._stopping = True

    def run_forever(self) -> None:
        """Run callbacks, timers and fd events until :meth:`stop`."""
        if self._closed:
            raise RuntimeError("the event loop is closed")
        if self._thread_id is not None:
            raise RuntimeError("the event loop is already running")
        self._thread_id = threading.get_ident()
        _current.loop = self
        try:
            while not self._stopping:
                self._run_once()
        finally:
            self._stopping = False
            self._thread_id = None
            _current.loop = None

    def run_until_complete(self, awaitable: Any) -> Any:
        """Run until ``awaitable`` (a coroutine or a future of this loop) is done; return its result."""
        future = awaitable if isinstance(awaitable, Future) else self.create_task(awaitable)
        future.add_done_callback(lambda _: self.stop())
        self.run_forever()
        if not future.done():
            raise RuntimeError("the event loop stopped before the future completed")
        return future.result()

    def shutdown_tasks(self, grace: float = 1.0) -> None:
        """Cancel every pending task and run the loop until they have finished (at most ``grace`` s)."""
        tasks = list(self._tasks)
        for task in tasks:
            task.cancel()
        deadline = time.monotonic() + grace
        self._thread_id = threading.get_ident()
        _current.loop = self
        try:
            while self._tasks and time.monotonic() < deadline:
                self._run_once(0.05)
        finally:
            self._thread_id = None
            _current.loop = None
        for task in list(self._tasks):  # stuck in a try/finally that awaits forever: let go
            _log.debug("task %r still pending at loop shutdown", task)
            task._coro.close()
            self._tasks.discard(task)

    def close(self) -> None:
        """Release the selector and the wake-up pipe; pending callbacks are dropped."""
        if self._closed:
            return
        if self._thread_id is not None:
            raise RuntimeError("cannot close a running event loop")
        with self._wake_lock:
            self._closed = True
            os.close(self._wake_r)
            os.close(self._wake_w)
        self._ready.clear()
        self._timers.clear()
        self._selector.close()

    def _run_once(self, max_wait: float | None = None) -> None:
        timers = self._timers
        if self._ready or self._stopping:
            wait: float | None = 0.0
        elif timers:
            wait = max(0.0, timers[0].when - time.monotonic())
            if max_wait is not None:
                wait = min(wait, max_wait)
        else:
            wait = max_wait
        ready = self._ready
        for key, mask in self._selector.select(wait):
            reader, writer = key.data
            if mask & selectors.EVENT_READ and reader is not None:
                ready.append(reader)
            if mask & selectors.EVENT_WRITE and writer is not None:
                ready.append(writer)
        if timers:
            now = time.monotonic()
            while timers and timers[0].when <= now:
                timer = heapq.heappop(timers)
                if timer._cancelled:
                    self._cancelled_timers -= 1
                else:
                    ready.append(timer)
        for _ in range(len(ready)):
            handle = ready.popleft()
            if not handle._cancelled:
                handle._run()

    def _wake(self) -> None:
        try:
            os.write(self._wake_w, b"\0")
        except (BlockingIOError, InterruptedError):
            pass  # the pipe is full: the loop is awake anyway
        except OSError:
            pass  # closed concurrently

    def _drain_wakeups(self) -> None:
        try:
            while os.read(self._wake_r, 4096):
                pass
        except (BlockingIOError, InterruptedError):
            pass


def _events(pair: tuple[Handle | None, Handle | None]) -> int:
    return (selectors.EVENT_READ if pair[0] is not None else 0) | (
        selectors.EVENT_WRITE if pair[1] is not None else 0
    )


def _fileno(fd: Any) -> int:
    return fd if isinstance(fd, int) else fd.fileno()


def _retry_call(future: Future, call: Callable[..., Any], args: tuple[Any, ...]) -> None:
    if future.done():
        return
    try:
        value = call(*args)
    except (BlockingIOError, InterruptedError):
        return
    except BaseException as exc:
        future.set_exception(exc)
    else:
        future.set_result(value)


def _connect_result(sock: socket.socket, address: Any) -> None:
    error = sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
    if error:
        raise OSError(error, f"connect to {address}: {os.strerror(error)}")


def is_numeric_host(host: Any) -> bool:
    """True for an IPv4/IPv6 address literal (or a non-string): nothing to look up."""
    if isinstance(host, bytes):
        host = host.decode("ascii", "replace")
    if not isinstance(host, str):
        return True
    for family in (socket.AF_INET, socket.AF_INET6):
        try:
            socket.inet_pton(family, host.partition("%")[0])
            return True
        except OSError:
            continue
    return False
