"""``roslib.packages``: where a package is (``get_pkg_dir``)."""

from __future__ import annotations

import rospkg

__all__ = ["InvalidROSPkgException", "ROSPkgException", "get_pkg_dir"]


class ROSPkgException(Exception):
    """Base of roslib.packages' errors."""


class InvalidROSPkgException(ROSPkgException):
    """A package that cannot be found."""


def get_pkg_dir(
    package: str, required: bool = True, ros_root: str | None = None, ros_package_path: str | None = None
) -> str | None:
    """The directory of ``package``; when it is nowhere, InvalidROSPkgException if ``required``, else None."""
    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        if required:
            raise InvalidROSPkgException(f"Cannot locate installation of package {package}") from None
        return None
