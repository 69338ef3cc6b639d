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

from ninjemys import interrupt
from ninjemys.interrupt import wait_event


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


def stop_signals() -> threading.Event:
    """From now on SIGINT and SIGTERM set the returned Event instead of raising.

    A page tool calls this before it starts its server: a Ctrl-C landing between the server's start
    and the wait would otherwise raise KeyboardInterrupt where nothing stops the server, and the node
    would leave without unregistering from the master."""
    stopped = interrupt.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stopped.set())
    return stopped


def serve_until_stopped(
    url: str, open_browser: bool, stop: Callable[[], None], stopped: threading.Event
) -> int:
    """The tail every page tool shares: open ``url`` (when asked and there is a display), wait for
    ``stopped`` (from :func:`stop_signals`: SIGTERM or Ctrl-C, as closing a ROS GUI tool's window),
    then ``stop`` the server; exit status 0."""
    try:
        if open_browser:
            open_if_display(url)
        wait_event(stopped)
    finally:
        stop()
    return 0
