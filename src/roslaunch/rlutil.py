"""roslaunch.rlutil: the helpers ROS 1 scripts call before launching (run id, launch file arguments)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import rosgraph
import rospkg
from ninjemys.errors import NinjemysError
from ninjemys.packages.discovery import PackageIndex

from .core import RLException, generate_run_id

__all__ = ["get_or_generate_uuid", "resolve_launch_arguments", "DEFAULT_MASTER_PORT"]

DEFAULT_MASTER_PORT = 11311


def get_or_generate_uuid(options_runid: str | None, options_wait_for_master: bool) -> str:
    """``options_runid`` if given, else the running master's ``/run_id``, else (no master and not
    waiting for one) a new run id. With ``options_wait_for_master`` it waits for a master."""
    if options_runid:
        return options_runid
    master = rosgraph.Master("/roslaunch")
    while True:
        try:
            return master.getParam("/run_id")
        except Exception:  # noqa: BLE001  (ROS 1: no master or no /run_id alike)
            if not options_wait_for_master:
                return generate_run_id()


def _find_in_package(package: str, name: str) -> list[str]:
    try:
        root = PackageIndex.from_environment().find(package).path
    except NinjemysError:
        raise rospkg.ResourceNotFound(package) from None
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        if name in filenames:
            found.append(os.path.join(dirpath, name))
    return found


def resolve_launch_arguments(args: Sequence[str]) -> list[str]:
    """``[file, launch args...]`` from ``roslaunch``'s positional arguments: ``PKG FILE args...`` (the
    file found inside the package) or ``FILE args...``; RLException when neither names a file."""
    args = rosgraph.myargv(list(args))
    if not args:
        return args
    resolved = None
    if len(args) >= 2:
        try:
            found = _find_in_package(args[0], args[1])
        except rospkg.ResourceNotFound:
            found = []
        if len(found) > 1:
            listing = "".join(f"\n- {r}" for r in found)
            raise RLException(
                f"multiple files named [{args[1]}] in package [{args[0]}]:{listing}\nPlease specify full path instead"
            )
        if len(found) == 1:
            resolved = [found[0], *args[2:]]
    if resolved is None and (args[0] == "-" or os.path.isfile(args[0])):
        resolved = list(args)
    if resolved is None:
        if len(args) >= 2:
            raise RLException(
                f"[{args[1]}] is neither a launch file in package [{args[0]}] nor is [{args[0]}] a launch file name"
            )
        raise RLException(f"[{args[0]}] is not a launch file name")
    return resolved
