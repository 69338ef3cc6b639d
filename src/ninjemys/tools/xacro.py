"""``xacro`` (also ``rosrun xacro xacro``, legacy ``xacro.py`` and ``$(find xacro)/xacro`` in launch files).

The macro language is the upstream xacro project's own implementation (the ``xacro`` package on
PyPI, the same code ROS ships), so every construct expands exactly as the field's xacro expands
it. That release resolves ``$(find pkg)`` through ``ament_index_python``; ninjemys provides that one
call (:mod:`ament_index_python.packages`) with ROS 1's rules: the workspaces on ROS_PACKAGE_PATH,
then ninjemys' own packages (``rospack find``). So the command and ``xacro.process_file`` in a
user's script resolve packages the same way, and xacro's code is used unchanged.
"""

from __future__ import annotations

import sys

from ninjemys.commands import entry


def main(argv: list[str] | None = None) -> int:
    """Run xacro's own command line; its exit code is xacro's (2 on an error it reports)."""
    import xacro

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
