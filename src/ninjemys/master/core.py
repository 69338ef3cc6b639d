"""The master as a running service: the XML-RPC server, the handler and the notifier on one event loop.

:class:`Master` is used by ``roscore`` (on the main thread's loop) and :class:`MasterThread` runs one
on a private loop in a background thread, for tests and for embedding a master in another program.
"""

from __future__ import annotations

import asyncio
import threading
from typing import Any

from ninjemys.master.notify import Notifier
from ninjemys.master.server import MasterHandler
from ninjemys.net.xmlrpc_server import XmlRpcServer

DEFAULT_PORT = 11311


class Master:
    """A master bound to ``host:port``; ``stopped`` is set when it shuts down (``shutdown`` call or :meth:`stop`)."""

    def __init__(
        self,
        host: str = "0.0.0.0",
        port: int = DEFAULT_PORT,
        *,
        advertise: str | None = None,
        notify_timeout: float = 10.0,
    ) -> None:
        self.handler = MasterHandler(on_shutdown=self._stop_soon)
        self.handler.notifier = Notifier(
            timeout=notify_timeout, on_param_rejected=self.handler._param_rejected
        )
        self.server = XmlRpcServer(self.handler, host, port, advertise=advertise)
        self.stopped: asyncio.Event | None = None
        self.reason = ""

    async def start(self) -> str:
        """Bind and serve; returns the master URI. ``OSError`` if the port is taken."""
        self.stopped = asyncio.Event()
        await self.server.start()
        self.handler.uri = self.server.uri
        return self.handler.uri

    @property
    def uri(self) -> str:
        return self.handler.uri

    def set_param(self, key: str, value: Any) -> None:
        """Set a parameter directly (what roscore does for /run_id, /rosdistro, /rosversion)."""
        self.handler.params.set(key, value)

    def _stop_soon(self, reason: str) -> None:
        """``shutdown`` RPC: answer the caller first, then stop."""
        asyncio.get_running_loop().call_soon(self.stop, reason)

    def stop(self, reason: str = "") -> None:
        """Stop serving (idempotent; must be called on the master's loop)."""
        if self.stopped is None or self.stopped.is_set():
            return
        self.reason = reason
        self.server.close()
        self.handler.notifier.close()
        self.stopped.set()

    async def serve_until_stopped(self) -> None:
        assert self.stopped is not None, "start() first"
        await self.stopped.wait()
        await self.server.wait_closed()


class MasterThread:
    """A master on its own event loop in a daemon thread: ``with MasterThread() as uri: ...``."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0, advertise: str | None = "127.0.0.1") -> None:
        self.master = Master(host, port, advertise=advertise)
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._run, name="ninjemys-master", daemon=True)
        self._ready = threading.Event()
        self._error: BaseException | None = None

    def _run(self) -> None:
        asyncio.set_event_loop(self.loop)
        try:
            self.loop.run_until_complete(self.master.start())
        except BaseException as exc:
            self._error = exc
            self._ready.set()
            return
        self._ready.set()
        self.loop.run_until_complete(self.master.serve_until_stopped())
        self.loop.run_until_complete(asyncio.sleep(0))
        self.loop.close()

    def start(self) -> str:
        self._thread.start()
        self._ready.wait()
        if self._error is not None:
            raise self._error
        return self.master.uri

    def stop(self) -> None:
        if self._thread.is_alive():
            self.loop.call_soon_threadsafe(self.master.stop, "MasterThread.stop")
            self._thread.join(5)

    def __enter__(self) -> str:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
