"""The ``rqt_graph`` command: prints the URL, serves the graph page and its gateway, exits 0 on
Ctrl-C; bad port -> one-line error."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import urllib.request

from websockets.sync.client import connect

from ninjemys.testing import free_port, ninjemys_bin, run_master, wait_until


def test_rqt_graph_serves_and_exits_cleanly() -> None:
    with run_master() as uri:
        port = free_port()
        proc = subprocess.Popen(
            [ninjemys_bin("rqt_graph"), "--no-browser", "--port", str(port)],
            env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stdout is not None
            line = proc.stdout.readline()
            assert line.strip() == f"rqt_graph: node graph of {uri} at http://localhost:{port}/"

            def rosout_published() -> bool:
                # run_master() returns once the master answers; rosout registers a moment later
                with connect(f"ws://localhost:{port}/ws", subprotocols=["foxglove.websocket.v1"]) as ws:
                    ws.send(json.dumps({"op": "subscribeConnectionGraph"}))
                    while True:
                        msg = json.loads(ws.recv(timeout=5))
                        if msg["op"] == "connectionGraphUpdate":
                            return any(t["name"] == "/rosout" for t in msg["publishedTopics"])

            assert wait_until(rosout_published, what="the gateway's graph showing our roscore's /rosout")
            with urllib.request.urlopen(f"http://localhost:{port}/", timeout=5) as page:
                assert b"graph.js" in page.read()
            proc.send_signal(signal.SIGINT)
            assert proc.wait(10) == 0
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_port_in_use_is_one_line_error() -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        done = subprocess.run(
            [ninjemys_bin("rqt_graph"), "--no-browser", "--port", str(port)],
            env=dict(os.environ, ROS_MASTER_URI=f"http://localhost:{free_port()}/"),
            capture_output=True,
            text=True,
            timeout=20,
        )
    assert done.returncode == 1
    assert done.stderr.startswith("ERROR: cannot serve the web tools on 127.0.0.1:")
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
