"""The subscription worker's poller on a system without epoll (macOS, Windows): the ``selectors``
fallback must register, report, unregister and close like the epoll path."""

from __future__ import annotations

import select
import socket

import pytest

from ninjemys.node import subscriber


@pytest.mark.parametrize("use_epoll", [True, False])
def test_poller_reports_ready_sockets_and_closes(monkeypatch: pytest.MonkeyPatch, use_epoll: bool) -> None:
    if not use_epoll:
        monkeypatch.delattr(select, "epoll", raising=False)
    elif not hasattr(select, "epoll"):
        pytest.skip("no epoll here")
    poller = subscriber._Poller()
    assert (poller.epoll is not None) is use_epoll
    a, b = socket.socketpair()
    wake_r, wake_w = socket.socketpair()
    try:
        marker = object()
        poller.register(a.fileno(), marker)  # type: ignore[arg-type]
        poller.register(wake_r.fileno(), None)
        b.send(b"x")
        wake_w.send(b"!")
        assert sorted(poller.wait(), key=lambda o: o is None) == [marker, None]
        poller.unregister(a.fileno())
        poller.unregister(a.fileno())  # twice is harmless
        a.recv(1)
        b.send(b"y")
        assert poller.wait() == [None]
    finally:
        poller.close()
        for s in (a, b, wake_r, wake_w):
            s.close()
