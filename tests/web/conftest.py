"""Fixtures for the web tools tests: a real ROS 1 master, real rospy nodes, a headless chromium."""

from __future__ import annotations

import signal
import subprocess
from collections.abc import Callable, Iterator
from typing import Any

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


class _SharedChromium:
    """One headless Chromium for a run of consecutive browser tests (each gets its own context).

    Launching Playwright's driver and Chromium costs ~1.5 s a test on the 2-core machine; a fresh
    browser *context* (its own cookies, storage, cache, permissions) is the isolation a test needs.
    The browser is closed as soon as the next test does not use ``browser_page`` (see
    :func:`pytest_runtest_teardown`): while Playwright's sync API is alive it marks its event loop
    as running on the main thread, which must not leak into other tests' ``asyncio.run``. After a
    failed test, or if Chromium went away, the next test gets a new browser."""

    def __init__(self) -> None:
        self._pw: Any = None
        self.browser: Any = None

    def get(self) -> Any:
        if self.browser is not None and not self.browser.is_connected():
            self.close()
        if self.browser is None:
            sync_api = pytest.importorskip("playwright.sync_api")
            self._pw = sync_api.sync_playwright().start()
            try:
                self.browser = self._pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
            except BaseException:
                self.close()
                raise
        return self.browser

    def close(self) -> None:
        browser, pw = self.browser, self._pw
        self.browser = self._pw = None
        try:
            if browser is not None and browser.is_connected():
                browser.close()
        finally:
            if pw is not None:
                pw.stop()


_CHROMIUM = _SharedChromium()
_FAILED = pytest.StashKey[bool]()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    report = yield
    if report.failed:
        item.stash[_FAILED] = True
    return report


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item: pytest.Item, nextitem: pytest.Item | None) -> Any:
    """After the test's own fixtures are gone: keep Chromium only for a next browser test."""
    try:
        return (yield)
    finally:
        keep = nextitem is not None and "browser_page" in getattr(nextitem, "fixturenames", ())
        if not keep or item.stash.get(_FAILED, False):
            _CHROMIUM.close()


@pytest.fixture
def browser_page() -> Iterator[Any]:
    """A fresh page, in a fresh context, of Debian's headless chromium, driven by Playwright."""
    if not CHROMIUM.exists():
        pytest.skip("Debian chromium is not installed (make test installs it)")
    context = _CHROMIUM.get().new_context(viewport={"width": 1200, "height": 800})
    try:
        yield context.new_page()
    finally:
        context.close()
