"""``rossrv``: the service side of :mod:`ninjemys.tools.rosmsg` (same commands, same output as ROS 1)."""

from __future__ import annotations

from ninjemys.tools.cli import entry
from ninjemys.tools.rosmsg import main_srv


def main(argv: list[str] | None = None) -> int:
    """``rossrv show|md5|list|package|packages ...``."""
    return main_srv(argv)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
