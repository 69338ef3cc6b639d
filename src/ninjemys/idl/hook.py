"""The import hook for interface packages, installable without importing the interface loader.

``import rospy`` installs it so ``from my_pkg.msg import MyMsg`` works for packages on
ROS_PACKAGE_PATH. Installing :class:`ninjemys.idl.loader.InterfaceFinder` directly would import the
loader (parser, code generator, md5, code cache: ~10 ms) in every process, including those that never
import an interface package. This finder decides with the package search alone (``idl.search``:
``os`` and ``re``, already loaded) and imports the loader only to create a module it found.

It must never import anything for names that are not interface packages: it is the last entry of
``sys.meta_path``, so it is asked about every module nobody else finds (``nt`` while pathlib is being
imported, optional C accelerators, ...), possibly while another thread is importing the loader; an
import from here at that moment could deadlock on the module import locks.
"""

from __future__ import annotations

import sys

from ninjemys.idl import search

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any


def interface_package(fullname: str) -> bool:
    """True if ``fullname`` is ``<pkg>``, ``<pkg>.msg`` or ``<pkg>.srv`` of a known interface package."""
    parts = fullname.split(".")
    if len(parts) > 2 or (len(parts) == 2 and parts[1] not in ("msg", "srv")):
        return False
    try:
        pkg = search.packages().get(parts[0])
    except OSError:
        return False
    if pkg is None:
        return False
    return len(parts) == 2 or any(pkg.definitions(kind) for kind in ("msg", "srv", "action"))


class LazyInterfaceFinder:
    """A MetaPathFinder for ``<pkg>``, ``<pkg>.msg`` and ``<pkg>.srv`` of interface packages."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        if not interface_package(fullname):
            return None
        from ninjemys.idl.loader import interface_module_spec

        return interface_module_spec(fullname)


def install() -> None:
    """Append the finder to ``sys.meta_path`` unless an interface finder is already there (idempotent)."""
    for finder in sys.meta_path:
        if type(finder).__name__ in ("LazyInterfaceFinder", "InterfaceFinder"):
            return
    sys.meta_path.append(LazyInterfaceFinder())
