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
from dataclasses import dataclass
from pathlib import Path

from ninjemys.errors import TypeNotFoundError

SHIPPED_ROOT = Path(__file__).resolve().parent.parent / "interfaces"
_NAME_RE = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_MAX_DEPTH = 8


@dataclass(frozen=True, slots=True)
class Package:
    name: str
    path: Path
    origin: str  # "shipped", "ROS_PACKAGE_PATH" or "CMAKE_PREFIX_PATH"

    def definitions(self, kind: str) -> dict[str, Path]:
        """``{"Type": path}`` of the ``.msg``/``.srv``/``.action`` files (kind is the suffix without dot)."""
        folder = self.path / kind
        try:
            return {p.stem: p for p in sorted(folder.glob(f"*.{kind}")) if p.is_file()}
        except OSError:
            return {}


def _package_name(package_xml: Path) -> str:
    try:
        match = _NAME_RE.search(package_xml.read_text(encoding="utf-8", errors="replace"))
    except OSError:
        match = None
    return match.group(1) if match else package_xml.parent.name


def _scan(root: Path, found: dict[str, Package], origin: str, depth: int = 0) -> None:
    if depth > _MAX_DEPTH or not root.is_dir():
        return
    manifest = root / "package.xml"
    if manifest.is_file():
        found.setdefault(_package_name(manifest), Package(_package_name(manifest), root, origin))
        return
    if (root / "CATKIN_IGNORE").exists() or (root / "rospack_nosubdirs").exists():
        return
    try:
        children = sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith("."))
    except OSError:
        return
    for child in children:
        _scan(child, found, origin, depth + 1)


def _shipped() -> dict[str, Package]:
    found: dict[str, Package] = {}
    if SHIPPED_ROOT.is_dir():
        for child in sorted(SHIPPED_ROOT.iterdir()):
            if (child / "package.xml").is_file():
                found[child.name] = Package(child.name, child, "shipped")
    return found


_lock = threading.Lock()
_cache: dict[tuple[str, str], dict[str, Package]] = {}


def search_roots() -> list[tuple[str, Path]]:
    """The places searched, in order, as (origin, path), for error messages and ``rosmsg``."""
    roots: list[tuple[str, Path]] = [("shipped", SHIPPED_ROOT)]
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry:
            roots.append(("ROS_PACKAGE_PATH", Path(entry)))
    for entry in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        if entry:
            roots.append(("CMAKE_PREFIX_PATH", Path(entry) / "share"))
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
            if root.is_dir():
                for child in sorted(root.iterdir()):
                    manifest = child / "package.xml"
                    if manifest.is_file():
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


def find_definition(package: str, short: str, kind: str) -> Path:
    """The file defining ``package/short`` of the given kind (``msg``, ``srv`` or ``action``)."""
    pkg = find_package(package)
    path = pkg.definitions(kind).get(short)
    if path is None:
        raise TypeNotFoundError(
            f"{kind} type {package}/{short} not found: package {package} at {pkg.path} has no "
            f"{kind}/{short}.{kind}"
        )
    return path
