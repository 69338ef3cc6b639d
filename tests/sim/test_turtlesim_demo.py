"""``make demo`` (``python -m ninjemys.demo``): turtlesim, the square driver and the chatter nodes; URLs printed, Ctrl-C stops all."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import urllib.request

from ninjemys.testing import free_port, wait_until


def _children(pid: int) -> set[int]:
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout
    return {int(p) for p in out.split()}


def test_demo_drives_the_square_and_stops_cleanly(tmp_path) -> None:  # type: ignore[no-untyped-def]
    port, web = free_port(), free_port()
    log = tmp_path / "demo.log"
    with open(log, "wb") as out:
        demo = subprocess.Popen(
            [sys.executable, "-m", "ninjemys.demo", "--chatter", "--port", str(port), "--web-port", str(web)],
            env=dict(os.environ, PYTHONUNBUFFERED="1"),
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
        )
    children: set[int] = set()
    try:
        wait_until(lambda: b"Ctrl-C stops the demo" in log.read_bytes(), timeout=30, what="the demo banner")
        text = log.read_text()
        assert f"turtlesim view: http://localhost:{web}/turtlesim" in text
        assert f"node graph: http://localhost:{web}/" in text
        children = _children(demo.pid)

        # the view's page is served (its data comes through the gateway), and turtle1 drives
        with urllib.request.urlopen(f"http://localhost:{web}/turtlesim", timeout=5) as page:
            assert b"turtlesim.js" in page.read()
        from ninjemys.node import Node
        from turtlesim.msg import Pose

        poses: list[float] = []
        node = Node("demo_watcher", anonymous=True, master_uri=f"http://localhost:{port}/")
        try:
            node.subscriber("/turtle1/pose", Pose, lambda m: poses.append(m.x), queue_size=10)
            wait_until(lambda: poses and poses[-1] > 5.8, timeout=20, what="turtle1 to drive")
        finally:
            node.shutdown("test over")
        demo.send_signal(signal.SIGINT)
        assert demo.wait(20) == 0
        for pid in children:
            wait_until(
                lambda p=pid: not os.path.exists(f"/proc/{p}") or _zombie(p),
                timeout=10,
                what="children to exit",
            )
    finally:
        if demo.poll() is None:
            demo.kill()
            demo.wait()
        for pid in children:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def _zombie(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True
