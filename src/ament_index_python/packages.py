"""``get_package_share_directory``: a package's directory as ``rospack find`` gives it."""

from __future__ import annotations

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex


class PackageNotFoundError(PackageError, KeyError):
    """A package that is neither on ROS_PACKAGE_PATH nor shipped with ninjemys (a KeyError, as in ament)."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


def get_package_share_directory(package_name: str) -> str:
    """The package's directory: the first workspace on ROS_PACKAGE_PATH that has it, else ninjemys' own."""
    manifest = PackageIndex.from_environment().packages.get(package_name)
    if manifest is None:
        raise PackageNotFoundError(
            f"package '{package_name}' not found: not on ROS_PACKAGE_PATH and not shipped with ninjemys"
        )
    return str(manifest.path)
