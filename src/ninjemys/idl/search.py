"""Where interface definitions are found.

In order (the first package of a name wins):

1. the definitions shipped inside ninjemys (``ninjemys/interfaces/<pkg>/``), so ``std_msgs`` & co
   work right after ``pip install``;
2. every entry of ``ROS_PACKAGE_PATH``: a directory with a ``package.xml`` is a package (its name is
   the ``<name>`` in package.xml) and is not searched further; other directories are searched
   recursively like rospack does (hidden directories and those with ``CATKIN_IGNORE`` or
   ``rospack_nosubdirs`` are skipped);
3. sourced workspaces and install prefixes: ``share/<pkg>/`` under every ``CMAKE_PREFIX_PATH`` entry.

A package's definitions live in its ``msg/``, ``srv/`` and ``action/`` directories. Scans are cached
per value of the environment variables, so changing ``ROS_PACKAGE_PATH`` at run time is honoured.
"""

from __future__ import annotations

import os
import re
import threading

from ninjemys.errors import TypeNotFoundError

#: plain ``os.path`` strings throughout: importing pathlib would be most of this module's start-up cost
SHIPPED_ROOT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "interfaces")
_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_MAX_DEPTH = 8


class Package:
    """A package that may hold interface definitions: its name, directory and where it was found."""

    __slots__ = ("name", "path", "origin")

    def __init__(self, name: str, path: str, origin: str) -> None:
        self.name = name
        self.path = path
        self.origin = origin  # "shipped", "ROS_PACKAGE_PATH" or "CMAKE_PREFIX_PATH"

    def __repr__(self) -> str:
        return f"Package({self.name!r}, {self.path!r}, {self.origin!r})"

    def definitions(self, kind: str) -> dict[str, str]:
        """``{"Type": path}`` of the ``.msg``/``.srv``/``.action`` files (kind is the suffix without dot)."""
        folder = os.path.join(self.path, kind)
        suffix = "." + kind
        try:
            names = sorted(os.listdir(folder))
        except OSError:
            return {}
        found = {}
        for name in names:
            full = os.path.join(folder, name)
            if name.endswith(suffix) and os.path.isfile(full):
                found[name[: -len(suffix)]] = full
        return found


def _package_name(package_xml: str) -> str:
    try:
        with open(package_xml, encoding="utf-8", errors="replace") as f:
            match = _NAME_RE.search(f.read())
    except OSError:
        match = None
    return match.group(1) if match else os.path.basename(os.path.dirname(package_xml))


def _subdirs(root: str) -> list[str]:
    try:
        names = sorted(os.listdir(root))
    except OSError:
        return []
    return [
        os.path.join(root, n) for n in names if not n.startswith(".") and os.path.isdir(os.path.join(root, n))
    ]


def _scan(root: str, found: dict[str, Package], origin: str, depth: int = 0) -> None:
    if depth > _MAX_DEPTH or not os.path.isdir(root):
        return
    manifest = os.path.join(root, "package.xml")
    if os.path.isfile(manifest):
        name = _package_name(manifest)
        found.setdefault(name, Package(name, root, origin))
        return
    if os.path.exists(os.path.join(root, "CATKIN_IGNORE")) or os.path.exists(
        os.path.join(root, "rospack_nosubdirs")
    ):
        return
    for child in _subdirs(root):
        _scan(child, found, origin, depth + 1)


def _shipped() -> dict[str, Package]:
    found: dict[str, Package] = {}
    for child in _subdirs(SHIPPED_ROOT):
        if os.path.isfile(os.path.join(child, "package.xml")):
            name = os.path.basename(child)
            found[name] = Package(name, child, "shipped")
    return found


_lock = threading.Lock()
_cache: dict[tuple[str, str], dict[str, Package]] = {}


def search_roots() -> list[tuple[str, str]]:
    """The places searched, in order, as (origin, path), for error messages and ``rosmsg``."""
    roots: list[tuple[str, str]] = [("shipped", SHIPPED_ROOT)]
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            roots.append(("ROS_PACKAGE_PATH", entry))
    for entry in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        if entry:
            roots.append(("CMAKE_PREFIX_PATH", os.path.join(entry, "share")))
    return roots


def packages() -> dict[str, Package]:
    """Every known package, by name, in search order (shipped first)."""
    key = (os.environ.get("ROS_PACKAGE_PATH", ""), os.environ.get("CMAKE_PREFIX_PATH", ""))
    with _lock:
        hit = _cache.get(key)
        if hit is not None:
            return hit
    found = _shipped()
    for origin, root in search_roots()[1:]:
        if origin == "CMAKE_PREFIX_PATH":
            # an install/devel prefix: share/<pkg>/package.xml, one level only
            for child in _subdirs(root):
                manifest = os.path.join(child, "package.xml")
                if os.path.isfile(manifest):
                    name = _package_name(manifest)
                    found.setdefault(name, Package(name, child, origin))
        else:
            _scan(root, found, origin)
    with _lock:
        _cache[key] = found
    return found


def clear_cache() -> None:
    """Forget scanned packages (after creating packages at run time, e.g. in tests)."""
    with _lock:
        _cache.clear()


def searched_description() -> str:
    """A one-line summary of where we looked, for TypeNotFoundError messages."""
    parts = [f"{origin}: {path}" for origin, path in search_roots()]
    return "; ".join(parts)


def find_package(name: str) -> Package:
    pkg = packages().get(name)
    if pkg is None:
        raise TypeNotFoundError(f"package {name!r} not found (searched {searched_description()})")
    return pkg


def find_definition(package: str, short: str, kind: str) -> str:
    """The file defining ``package/short`` of the given kind (``msg``, ``srv`` or ``action``)."""
    pkg = find_package(package)
    path = pkg.definitions(kind).get(short)
    if path is None:
        raise TypeNotFoundError(
            f"{kind} type {package}/{short} not found: package {package} at {pkg.path} has no "
            f"{kind}/{short}.{kind}"
        )
    return path
