"""``roslib.launcher.load_manifest``: a no-op for catkin packages once the package is found."""

from __future__ import annotations

import importlib.util

import rospkg

__all__ = ["load_manifest"]

_bootstrapped: list[str] = []


def load_manifest(package_name: str, bootstrap_version: str = "0.7") -> None:
    """Check that ``package_name`` exists (rospkg.ResourceNotFound if not); catkin packages need no
    path changes, their Python modules are importable already. A package whose Python module ninjemys
    ships without a package.xml (rospy, tf, actionlib ...) counts as found."""
    if package_name in _bootstrapped:
        return
    if importlib.util.find_spec(package_name) is None:
        rospkg.RosPack().get_path(package_name)
    _bootstrapped.append(package_name)
