"""Finding what ``rosrun PKG EXE`` and ``<node pkg type>`` run.

Search order (first hit wins, no interactive prompt as ROS 1's rosrun has on duplicates):
``devel/lib/<pkg>/`` of every devel space on CMAKE_PREFIX_PATH (what catkin_make installed), then the
package directory (``scripts/``, ``nodes/``, ``bin/``, ``src/`` first, then anywhere below it), then
the executables ninjemys ships (:mod:`ninjemys.packages.shipped`). Python scripts are run with the
interpreter ninjemys is installed in, so their ``import rospy`` is ours whatever the shebang says.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.manifest import PackageManifest
from ninjemys.packages.shipped import ShippedExecutable, shipped_executable

_PREFERRED_DIRS = ("scripts", "nodes", "bin", "src")
_SKIP_DIRS = {"build", "devel", "install", "__pycache__", "node_modules"}


@dataclass(frozen=True)
class Executable:
    """A runnable thing: a file in a package, or a module ninjemys ships."""

    package: str
    name: str
    path: Path | None = None
    shipped: ShippedExecutable | None = None

    @property
    def display_path(self) -> str:
        """What ROS 1 would print for it (``roslaunch --args``): the file, or the shipped command."""
        if self.path is not None:
            return str(self.path)
        assert self.shipped is not None
        return " ".join(self.shipped.command())

    def command(self, args: list[str] | tuple[str, ...] = ()) -> list[str]:
        """argv for the process; Python scripts run under ninjemys' interpreter."""
        if self.shipped is not None:
            return self.shipped.command(args)
        assert self.path is not None
        if is_python_script(self.path):
            return [sys.executable, str(self.path), *args]
        return [str(self.path), *args]


def is_python_script(path: Path) -> bool:
    """``*.py``, or a shebang naming python (``#!/usr/bin/env python3``)."""
    if path.suffix == ".py":
        return True
    try:
        with open(path, "rb") as f:
            first = f.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and b"python" in first


def devel_lib_dirs(package: str, env: Mapping[str, str] | None = None) -> list[Path]:
    """``<devel>/lib/<package>`` and ``<devel>/share/<package>`` for every prefix on
    CMAKE_PREFIX_PATH that has them (rosrun's ``catkin_find --libexec --share``: a script installed
    with ``DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/dir`` runs too)."""
    env = os.environ if env is None else env
    dirs = []
    for prefix in env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        for space in ("lib", "share"):
            if prefix and (Path(prefix) / space / package).is_dir():
                dirs.append(Path(prefix) / space / package)
    return dirs


def _walk_named(root: Path, name: str) -> list[Path]:
    preferred = [root / d for d in _PREFERRED_DIRS if (root / d).is_dir()]
    found: list[Path] = []
    if (root / name).is_file():
        found.append(root / name)
    for base in preferred:
        for dirpath, dirnames, filenames in os.walk(base, followlinks=True):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in _SKIP_DIRS)
            if name in filenames:
                found.append(Path(dirpath) / name)
    for dirpath, dirnames, filenames in os.walk(root, followlinks=True):
        here = Path(dirpath)
        dirnames[:] = sorted(
            d for d in dirnames if not d.startswith(".") and d not in _SKIP_DIRS and here / d not in preferred
        )
        if name in filenames and here / name not in found:
            found.append(here / name)
    return found


def candidates(manifest: PackageManifest, name: str, env: Mapping[str, str] | None = None) -> list[Path]:
    """Every file called ``name`` that rosrun would consider, best first."""
    found: list[Path] = []
    for lib in devel_lib_dirs(manifest.name, env):
        for dirpath, dirnames, filenames in os.walk(lib, followlinks=True):
            dirnames.sort()
            if name in filenames:
                found.append(Path(dirpath) / name)
    for path in _walk_named(manifest.path, name):
        if path not in found:
            found.append(path)
    return found


def find_executable(manifest: PackageManifest, name: str, env: Mapping[str, str] | None = None) -> Executable:
    """The executable ``name`` of the package, or PackageError saying what was found instead.

    A file that exists but is not executable gets ROS 1's hint: ``chmod +x``.
    """
    if "/" in name:
        raise PackageError(f"executable name [{name}] must not contain '/'")
    files = candidates(manifest, name, env)
    runnable = [f for f in files if os.access(f, os.X_OK)]
    if runnable:
        return Executable(manifest.name, name, path=runnable[0])
    shipped = shipped_executable(manifest.name, name)
    if shipped is not None:
        return Executable(manifest.name, name, shipped=shipped)
    if files:
        listing = ", ".join(str(f) for f in files)
        raise PackageError(
            f"Couldn't find executable named {name} below {manifest.path}: found {listing}, "
            f"but it is not executable (chmod +x {files[0]})"
        )
    raise PackageError(f"Couldn't find executable named {name} below {manifest.path}")
