"""``xacro`` (also ``rosrun xacro xacro`` and ``$(find xacro)/xacro`` in launch files).

The macro language is the upstream xacro project's own implementation (the ``xacro`` package on
PyPI, the same code ROS ships), so every construct expands exactly as the field's xacro expands
it. That release resolves ``$(find pkg)`` through ament (ROS 2); here it resolves through ROS 1's
rules instead: the workspaces on ROS_PACKAGE_PATH, then ninjemys' own packages (``rospack find``).
An unknown package is xacro's error naming it, with the file being processed.
"""

from __future__ import annotations

import sys

from ninjemys.commands import entry
from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex


def find_package(name: str) -> str:
    """``$(find name)``: the package's directory, as ``rospack find`` gives it."""
    manifest = PackageIndex.from_environment().packages.get(name)
    if manifest is None:
        raise PackageError(f"[{name}] not found: not on ROS_PACKAGE_PATH and not shipped with ninjemys")
    return str(manifest.path)


def install_find() -> None:
    """Route xacro's ``$(find)`` (both the substitution and ``${find('pkg')}`` in expressions)."""
    from xacro import substitution_args

    substitution_args._eval_find = find_package  # the function _find calls by its global name
    substitution_args._eval_dict["find"] = find_package


def main(argv: list[str] | None = None) -> int:
    """Run xacro's own command line with ROS 1's ``$(find)``; its exit code is xacro's."""
    import xacro

    install_find()
    args = sys.argv[1:] if argv is None else argv
    saved = sys.argv
    sys.argv = ["xacro", *args]
    try:
        xacro.main()
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        sys.argv = saved
    return 0


console_main = entry(main)
