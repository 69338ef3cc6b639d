"""The import hook for interface packages, installable without importing the interface loader.

``import rospy`` installs it so ``from my_pkg.msg import MyMsg`` works for packages on
ROS_PACKAGE_PATH. Installing :class:`ninjemys.idl.loader.InterfaceFinder` directly would import the
loader (parser, code generator, md5, code cache: ~10 ms) in every process, including those that never
look up an interface package; this finder imports it on the first lookup that could be one.
"""

from __future__ import annotations

import sys
from typing import Any


class LazyInterfaceFinder:
    """A MetaPathFinder that hands ``<pkg>``, ``<pkg>.msg`` and ``<pkg>.srv`` to the real finder."""

    def __init__(self) -> None:
        self._real: Any = None

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        parts = fullname.split(".")
        if len(parts) > 2 or (len(parts) == 2 and parts[1] not in ("msg", "srv")):
            return None
        if self._real is None:
            from ninjemys.idl.loader import InterfaceFinder

            self._real = InterfaceFinder()
        return self._real.find_spec(fullname, path, target)


def install() -> None:
    """Append the finder to ``sys.meta_path`` unless an interface finder is already there (idempotent)."""
    for finder in sys.meta_path:
        if type(finder).__name__ in ("LazyInterfaceFinder", "InterfaceFinder"):
            return
    sys.meta_path.append(LazyInterfaceFinder())
