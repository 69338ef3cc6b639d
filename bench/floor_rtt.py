"""The machine's floor for a small-message round trip in Python: what "near the floor" means here.

Two processes ping-pong 68 bytes (a 64-byte std_msgs/String frame) over a Unix stream socket, with
nothing else on the path. Three shapes, each on one CPU (``taskset -c 0``) and across two CPUs:

* ``bare``: each side one thread, blocking ``recv``/``send``: two wake-ups per round trip, the floor;
* ``epoll``: the same with the receiving side waiting in ``epoll`` first, as a node's reader does;
* ``thread+event``: the pinging side receives on a second thread and wakes its main thread with a
  ``threading.Event``, as the ping role of ``node_rtt.py`` (and every rospy/ninjemys node) must:
  three wake-ups per round trip, the floor of that benchmark's shape.

Run: ``.venv/bin/python bench/floor_rtt.py [count]``; compare with ``bench/node_rtt.py``.
"""

from __future__ import annotations

import os
import select
import socket
import subprocess
import sys
import threading
import time

FRAME = b"\x40\0\0\0" + b"x" * 64


def _pct(values: list[float], q: float) -> float:
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def pong(fd: int, shape: str) -> None:
    sock = socket.socket(fileno=fd)
    poller = select.epoll() if shape != "bare" else None
    if poller is not None:
        poller.register(sock.fileno(), select.EPOLLIN)
    while True:
        if poller is not None:
            poller.poll()
        data = sock.recv(4096)
        if not data:
            return
        sock.send(data)


def ping(sock: socket.socket, shape: str, count: int) -> list[float]:
    rtts: list[float] = []
    if shape == "thread+event":
        got = threading.Event()

        def reader() -> None:
            poller = select.epoll()
            poller.register(sock.fileno(), select.EPOLLIN)
            while True:
                poller.poll()
                if not sock.recv(4096):
                    return
                got.set()

        threading.Thread(target=reader, daemon=True).start()
        for i in range(count + 200):
            got.clear()
            t0 = time.perf_counter()
            sock.send(FRAME)
            got.wait()
            if i >= 200:
                rtts.append(time.perf_counter() - t0)
        return rtts
    for i in range(count + 200):
        t0 = time.perf_counter()
        sock.send(FRAME)
        sock.recv(4096)
        if i >= 200:
            rtts.append(time.perf_counter() - t0)
    return rtts


def run(shape: str, cpus: tuple[str, str], count: int) -> tuple[float, float]:
    a, b = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    child = subprocess.Popen(
        ["taskset", "-c", cpus[1], sys.executable, __file__, "--pong", str(b.fileno()), shape],
        pass_fds=(b.fileno(),),
    )
    b.close()
    os.sched_setaffinity(0, {int(cpus[0])})
    try:
        rtts = ping(a, shape, count)
    finally:
        a.close()
        child.wait()
        os.sched_setaffinity(0, set(range(os.cpu_count() or 1)))
    return _pct(rtts, 0.5) * 1e6, _pct(rtts, 0.99) * 1e6


def main() -> None:
    if sys.argv[1:2] == ["--pong"]:
        pong(int(sys.argv[2]), sys.argv[3])
        return
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 5000
    print(
        f"\n## floor: Python ping-pong over a Unix socket, {count} round trips (load {os.getloadavg()[0]:.1f})"
    )
    for shape in ("bare", "epoll", "thread+event"):
        for name, cpus in (("same CPU", ("0", "0")), ("across CPUs", ("0", "1"))):
            p50, p99 = run(shape, cpus, count)
            print(f"{shape:14s} {name:12s} p50 {p50:7.1f} us   p99 {p99:7.1f} us")


if __name__ == "__main__":
    main()
