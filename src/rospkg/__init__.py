"""ROS 1's ``rospkg``: find packages (``RosPack().get_path("my_pkg")``) and ROS's directories.

Packages are those ``rospack`` sees: ROS_PACKAGE_PATH (workspaces, in order) overlaying the ones
ninjemys ships (:mod:`ninjemys.packages.discovery`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex, package_path_dirs, underlay_dirs
from ninjemys.roshome import log_directory

__all__ = [
    "ResourceNotFound",
    "RosPack",
    "get_log_dir",
    "get_ros_home",
    "get_ros_package_path",
    "get_ros_paths",
]


class ResourceNotFound(Exception):
    """A package (or other resource) that is nowhere on the ROS paths; the text lists where was looked."""

    def __init__(self, msg: str, ros_paths: Sequence[str] | None = None) -> None:
        super().__init__(msg)
        self.ros_paths = list(ros_paths or [])

    def __str__(self) -> str:
        lines = [str(self.args[0])]
        lines += [f"ROS path [{i}]={p}" for i, p in enumerate(self.ros_paths)]
        return "\n".join(lines)


def get_ros_paths(env: Mapping[str, str] | None = None) -> list[str]:
    """Where packages are looked for, in precedence order."""
    return [str(p) for p in package_path_dirs(env) + underlay_dirs()]


def get_ros_package_path(env: Mapping[str, str] | None = None) -> str | None:
    """ROS_PACKAGE_PATH as set (None when unset)."""
    return (os.environ if env is None else env).get("ROS_PACKAGE_PATH")


def get_ros_home(env: Mapping[str, str] | None = None) -> str:
    """ROS_HOME, else ~/.ros."""
    env = os.environ if env is None else env
    return env.get("ROS_HOME") or str(Path.home() / ".ros")


def get_log_dir(env: Mapping[str, str] | None = None) -> str:
    """ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log."""
    return str(log_directory(env))


class RosPack:
    """The packages visible now (scanned once per instance, as rospkg caches them)."""

    def __init__(self, ros_paths: Sequence[str] | None = None) -> None:
        self._ros_paths = list(ros_paths) if ros_paths is not None else get_ros_paths()
        self._index = PackageIndex.scan([Path(p) for p in self._ros_paths])

    def get_ros_paths(self) -> list[str]:
        return list(self._ros_paths)

    def _manifest(self, name: str) -> Any:
        try:
            return self._index.find(name)
        except PackageError:
            raise ResourceNotFound(name, self._ros_paths) from None

    def get_path(self, name: str) -> str:
        """The directory of package ``name`` (ResourceNotFound if there is none)."""
        return str(self._manifest(name).path)

    def list(self) -> list[str]:
        """Every visible package name."""
        return self._index.names()

    def get_depends(self, name: str, implicit: bool = True) -> list[str]:
        """What ``name`` depends on (all the way down when ``implicit``), as ``rospack depends``."""
        self._manifest(name)
        return self._index.depends(name, recursive=implicit)

    def get_depends_on(self, name: str, implicit: bool = True) -> list[str]:
        """The packages that depend on ``name``, as ``rospack depends-on``."""
        self._manifest(name)
        return self._index.depends_on(name, recursive=implicit)

    def get_manifest(self, name: str) -> Any:
        """The package's parsed package.xml (name, version, path, dependencies ...)."""
        return self._manifest(name)
