"""ROS 1's ``roslib``: what ROS 1 programs still call from it.

``roslib.load_manifest("my_pkg")`` opens old scripts (the tf tutorials among them); with catkin
packages it only checks that the package exists (rospkg.ResourceNotFound otherwise), as in ROS 1.
``roslib.packages.get_pkg_dir`` and ``roslib.message.get_message_class`` are the other calls in use.
"""

from __future__ import annotations

from roslib import message, packages
from roslib.launcher import load_manifest

__all__ = ["is_interactive", "load_manifest", "message", "packages", "set_interactive"]

_is_interactive = False


def set_interactive(interactive: bool) -> None:
    """Declare that the program runs in an interactive shell (libraries may then skip signal handlers)."""
    global _is_interactive
    _is_interactive = interactive


def is_interactive() -> bool:
    return _is_interactive
