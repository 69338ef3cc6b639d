"""Fixtures for the web tools tests: a real ROS 1 master, real rospy nodes, a headless chromium."""

from __future__ import annotations

import signal
import subprocess
import time
import xmlrpc.client
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from ninjemys.testing import ROS1_PYTHON, free_port, ros1_env

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]

TALKER = """
import rospy
from std_msgs.msg import String
rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    pub.publish("hello world")
    rate.sleep()
"""

LISTENER = """
import rospy
from std_msgs.msg import String
rospy.init_node("listener")
rospy.Subscriber("chatter", String, lambda msg: None)
rospy.spin()
"""


def wait_for_master(uri: str, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            xmlrpc.client.ServerProxy(uri).getPid("/test")
            return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError(f"master at {uri} did not come up")


@pytest.fixture
def ros1_master() -> Iterator[str]:
    """Debian's rosmaster on a free port (no rosout: the graph tests do not need it)."""
    port = free_port()
    uri = f"http://localhost:{port}/"
    proc = subprocess.Popen(
        [ROS1_PYTHON, "/usr/bin/rosmaster", "--core", "-p", str(port)],
        env=ros1_env(uri),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_for_master(uri)
        yield uri
    finally:
        proc.kill()
        proc.wait()


@pytest.fixture
def rospy_node(ros1_master: str) -> Iterator[Callable[[str], subprocess.Popen]]:
    """Start a real rospy script against the test master; every process is killed at teardown."""
    procs: list[subprocess.Popen] = []

    def start(script: str) -> subprocess.Popen:
        proc = subprocess.Popen(
            [ROS1_PYTHON, "-c", script],
            env=ros1_env(ros1_master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        procs.append(proc)
        return proc

    try:
        yield start
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        for proc in procs:
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def wait_until(predicate: Callable[[], object], timeout: float = 20.0, what: str = "condition") -> object:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def browser_page():  # type: ignore[no-untyped-def]
    """A fresh page in Debian's headless chromium, driven by Playwright."""
    if not CHROMIUM.exists():
        pytest.skip("Debian chromium is not installed (make test installs it)")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 800})
            yield page
        finally:
            browser.close()
