"""The rqt commands: URL printed with the tool's arguments, rosrun forms, bags read server-side."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import urllib.request
from pathlib import Path
from urllib.parse import parse_qsl, urlsplit

import pytest

from ninjemys.bag.api import Bag
from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.rostime import Time
from ninjemys.serve.http import HttpError
from ninjemys.testing import free_port, ninjemys_bin, run_master
from ninjemys.web.rqt import Rqt


def _run(argv: list[str], uri: str) -> tuple[str, str, dict]:
    """Start a command, read its URL line, fetch the bag API, stop it with Ctrl-C (exit 0)."""
    proc = subprocess.Popen(
        argv,
        env=dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline().strip()
        url = line.split(": ", 1)[1]
        base = url.split("/rqt", 1)[0]
        with urllib.request.urlopen(base + "/api/rqt/bag", timeout=10) as resp:
            bag = json.load(resp)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(15) == 0
        assert proc.stderr is not None
        return line, proc.stderr.read(), bag
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_rqt_plot_prints_its_url_with_the_fields() -> None:
    with run_master() as uri:
        port = free_port()
        line, _err, _bag = _run(
            [
                ninjemys_bin("rqt_plot"),
                "--no-browser",
                "--port",
                str(port),
                "/turtle1/pose/x:y",
                "/odom/twist",
            ],
            uri,
        )
    assert line.startswith(f"rqt_plot: http://localhost:{port}/rqt?")
    query = parse_qsl(urlsplit(line.split(": ", 1)[1]).query)
    assert query == [
        ("tool", "plot"),
        ("topic", "/turtle1/pose/x"),
        ("topic", "/turtle1/pose/y"),
        ("topic", "/odom/twist"),
    ]


def test_rosrun_rqt_bag_names_a_bag_that_does_not_parse(tmp_path: Path) -> None:
    bad = tmp_path / "bad.bag"
    bad.write_text("hello")
    with run_master() as uri:
        line, err, bag = _run(
            [ninjemys_bin("rosrun"), "rqt_bag", "rqt_bag", "--no-browser", str(bad)],
            uri,
        )
    assert "/rqt?tool=bag" in line
    assert err.strip() == f"rqt_bag: {bad}: not a bag file (no '#ROSBAG V2.0' magic)"
    assert bag["errors"] == [f"{bad}: not a bag file (no '#ROSBAG V2.0' magic)"]


def test_axclient_needs_an_action_name() -> None:
    done = subprocess.run(
        [ninjemys_bin("rosrun"), "actionlib", "axclient.py", "--no-browser"],
        env=dict(os.environ, ROS_MASTER_URI=f"http://localhost:{free_port()}/"),
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 2
    assert "the following arguments are required: action" in done.stderr


def test_bag_session_index_and_messages(tmp_path: Path) -> None:
    path = tmp_path / "two.bag"
    cls = get_message_class("std_msgs/Int32")
    with Bag(str(path), "w") as bag:
        for i in range(5):
            bag.write("/count", cls(data=i), Time(10 + i, 0))
    with MasterThread() as uri:
        rqt = Rqt(uri, bags=[str(path)])
        try:
            session = rqt.page.bag
            info = session.info()
            assert info["start"] == 10 * 10**9 and info["end"] == 14 * 10**9
            assert [(t["name"], t["type"], t["count"]) for t in info["topics"]] == [
                ("/count", "std_msgs/Int32", 5)
            ]
            # the last message at or before the cursor; before the first one, the first
            assert session.message("/count", 12 * 10**9 + 5)["time"] == 12 * 10**9
            assert session.message("/count", 0)["time"] == 10 * 10**9
            assert len(session.messages("/count", 11 * 10**9, 13 * 10**9, 100)) == 3
            with pytest.raises(HttpError, match="topic /nope has no messages in the bag"):
                session.message("/nope", 0)
            with pytest.raises(HttpError, match="speed must be positive"):
                session.play(None, 0.0, False)
        finally:
            rqt.stop()


def test_rqt_standalone_opens_the_plugins_tab() -> None:
    with run_master() as uri:
        line, _err, _bag = _run([ninjemys_bin("rqt"), "--no-browser", "-s", "rqt_console"], uri)
    assert line.startswith("rqt: http://localhost:") and line.endswith("/rqt?tool=console")
    done = subprocess.run(
        [ninjemys_bin("rqt"), "--no-browser", "-s", "rqt_nope"], capture_output=True, text=True, timeout=30
    )
    assert done.returncode == 2
    assert "invalid choice: 'rqt_nope'" in done.stderr
