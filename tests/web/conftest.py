"""Fixtures for the web tools tests: a real ROS 1 master, real rospy nodes, a headless chromium."""

from __future__ import annotations

import signal
import subprocess
from collections.abc import Callable, Iterator

import pytest
from web_helpers import CHROMIUM, CHROMIUM_ARGS

from ninjemys.testing import ROS1_PYTHON, ros1_env, run_real_master


@pytest.fixture
def ros1_master() -> Iterator[str]:
    """Debian's rosmaster on a free port (no rosout: the graph tests do not need it)."""
    with run_real_master() as uri:
        yield uri


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
