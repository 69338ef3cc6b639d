"""Where our console scripts are: roslaunch starts ``roscore`` this way, tests start every command.

The venv's ``bin/`` next to the running interpreter comes first, so a process started from a venv
runs that venv's commands even when another ROS (Debian's ``/usr/bin/roscore``) is on PATH.
"""

from __future__ import annotations

import os
import shutil
import sys


def command_path(command: str) -> str:
    """Full path of one of our console scripts; FileNotFoundError if it is not installed."""
    candidate = os.path.join(os.path.dirname(sys.executable), command)
    if os.path.exists(candidate):
        return candidate
    found = shutil.which(command)
    if found is None:
        raise FileNotFoundError(f"ninjemys command {command!r} is not installed next to {sys.executable}")
    return found
