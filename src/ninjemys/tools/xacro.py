"""``xacro`` (also ``rosrun xacro xacro``, legacy ``xacro.py`` and ``$(find xacro)/xacro`` in launch files).

The macro language is the upstream xacro project's own implementation (the ``xacro`` package on
PyPI, the same code ROS ships), so every construct expands exactly as the field's xacro expands
it. That release resolves ``$(find pkg)`` through ``ament_index_python``; ninjemys provides that one
call (:mod:`ament_index_python.packages`) with ROS 1's rules: the workspaces on ROS_PACKAGE_PATH,
then ninjemys' own packages (``rospack find``). So the command and ``xacro.process_file`` in a
user's script resolve packages the same way, and xacro's code is used unchanged.

Two things of Noetic's command line are not in that release and are restored here, for the command
only: a package that ``$(find ...)`` cannot find is reported in Noetic's words (``resource not found:
pkg`` and the ROS paths searched, what users search the web for), and a missing input file is one
error line and exit 2, not a traceback (Noetic's xacro imported roslaunch, which loads the XML
parser module that xacro's error handler names; the PyPI release does not load it first).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from ninjemys.commands import entry
from ninjemys.errors import PackageError

_FIND = re.compile(r"\$\(\s*find\s+(\S+)\s*\)")


class ResourceNotFound(PackageError):
    """Noetic's ``rospkg`` error text: the package, then each ROS path searched on its own line."""

    def __init__(self, package: str, ros_paths: list[str]) -> None:
        super().__init__(package)
        self.ros_paths = ros_paths

    def __str__(self) -> str:
        lines = [str(self.args[0])]
        lines += [f"ROS path [{i}]={p}" for i, p in enumerate(self.ros_paths)]
        return "\n".join(lines)


def _ros_paths() -> list[str]:
    from ninjemys.packages.discovery import package_path_dirs, underlay_dirs

    return [str(p) for p in (*package_path_dirs(), *underlay_dirs())]


@contextmanager
def _noetic_messages(xacro: Any) -> Iterator[None]:
    """Report an unknown ``$(find pkg)`` as Noetic's xacro does, while the command runs."""
    from ament_index_python.packages import PackageNotFoundError

    original: Callable[[str], Any] = xacro.eval_extension

    def eval_extension(text: str) -> Any:
        try:
            return original(text)
        except xacro.XacroException as exc:
            found = _FIND.search(text)
            if isinstance(exc.exc, PackageNotFoundError) and found:
                missing = ResourceNotFound(found.group(1), _ros_paths())
                raise xacro.XacroException("resource not found:", exc=missing) from exc
            raise

    xacro.eval_extension = eval_extension
    try:
        yield
    finally:
        xacro.eval_extension = original


def main(argv: list[str] | None = None) -> int:
    """Run xacro's own command line; its exit code is xacro's (2 on an error it reports)."""
    import xml.parsers.expat  # noqa: F401  (xacro's error handler names it; see the module docstring)

    import xacro

    args = sys.argv[1:] if argv is None else argv
    saved = sys.argv
    sys.argv = ["xacro", *args]
    try:
        with _noetic_messages(xacro):
            xacro.main()
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        sys.argv = saved
    return 0


console_main = entry(main)
