"""Open a page the way a ROS GUI tool would pop up its window: only when there is a display.

On a headless machine (ssh, CI, containers) ``webbrowser`` could fall back to a text browser that takes
over the terminal, so without a display the URL is only printed.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import webbrowser
from collections.abc import Callable


def has_display() -> bool:
    return sys.platform in ("darwin", "win32") or bool(
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )


def open_if_display(url: str) -> bool:
    """Open ``url`` in the user's browser when there is a display; True if a browser was asked to."""
    if not has_display():
        return False
    try:
        return webbrowser.open(url)
    except webbrowser.Error:
        return False


def serve_until_stopped(url: str, open_browser: bool, stop: Callable[[], None]) -> int:
    """The tail every page tool shares: open ``url`` (when asked and there is a display), wait for
    SIGTERM or Ctrl-C as a ROS GUI tool's window would, then ``stop`` the server; exit status 0."""
    if open_browser:
        open_if_display(url)
    stopped = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stopped.set())
    try:
        stopped.wait()
    except KeyboardInterrupt:
        pass
    finally:
        stop()
    return 0
