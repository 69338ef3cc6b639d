"""Open a page the way a ROS GUI tool would pop up its window: only when there is a display.

On a headless machine (ssh, CI, containers) ``webbrowser`` could fall back to a text browser that takes
over the terminal, so without a display the URL is only printed.
"""

from __future__ import annotations

import os
import sys
import webbrowser


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
