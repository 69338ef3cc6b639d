"""Executables that ship inside ninjemys as Python modules, by ROS package name.

``rosrun turtlesim turtlesim_node`` and ``<node pkg="turtlesim" type="turtlesim_node"/>`` have no
file to execute: the node is ``ninjemys.sim.turtlesim_node:main``. This table maps
package -> executable -> :class:`ShippedExecutable`; :mod:`ninjemys.packages.run_shipped` is the
process entry point that imports the module and calls the function with the user's arguments.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class ShippedExecutable:
    """``target`` is ``"module:function"``; ``prefix_args`` go before the user's arguments."""

    package: str
    name: str
    target: str
    prefix_args: tuple[str, ...] = ()

    @property
    def module(self) -> str:
        return self.target.split(":", 1)[0]

    @property
    def function(self) -> str:
        return self.target.split(":", 1)[1]

    def command(self, args: list[str] | tuple[str, ...] = ()) -> list[str]:
        """The argv that runs this executable in a fresh interpreter (the one ninjemys runs in)."""
        return [sys.executable, "-m", "ninjemys.packages.run_shipped", self.package, self.name, *args]


def _table() -> dict[str, dict[str, ShippedExecutable]]:
    entries: dict[str, dict[str, tuple[str, tuple[str, ...]]]] = {
        "turtlesim": {
            "turtlesim_node": ("ninjemys.sim.turtlesim_node:main", ()),
            "turtle_teleop_key": ("ninjemys.sim.teleop_key:main", ()),
            "draw_square": ("ninjemys.sim.draw_square:main", ()),
            "mimic": ("ninjemys.sim.mimic:main", ()),
        },
        "rqt_graph": {"rqt_graph": ("ninjemys.web.rqt_graph:main", ())},
        "puzzlebot_sim": {
            "world_to_map": ("ninjemys.sim.world_to_map:main", ()),
        },
        "map_server": {
            "map_server": ("ninjemys.nav.map_server_node:main", ()),
            "map_saver": ("ninjemys.nav.map_server_node:saver_main", ()),
        },
        "amcl": {"amcl": ("ninjemys.nav.amcl_node:main", ())},
        "move_base": {"move_base": ("ninjemys.nav.move_base_node:main", ())},
        "gmapping": {"slam_gmapping": ("ninjemys.nav.slam_node:main", ())},
        "puzzlebot_safety": {"safety_monitor": ("ninjemys.nav.safety_node:main", ())},
        "rospy_tutorials": {
            name: (f"ninjemys.tutorials.{name.removesuffix('.py')}:main", ())
            for name in (
                "talker",
                "talker.py",
                "listener",
                "listener.py",
                "add_two_ints_server",
                "add_two_ints_client",
            )
        },
        "rosout": {"rosout": ("ninjemys.master.rosout:main", ())},
        "dynamic_reconfigure": {"dynparam": ("ninjemys.tools.dynparam:main", ())},
        "rosbag": {
            sub: ("ninjemys.tools.rosbag:main", (sub,))
            for sub in (
                "record",
                "play",
                "info",
                "check",
                "fix",
                "filter",
                "compress",
                "decompress",
                "reindex",
            )
        },
    }
    return {
        pkg: {name: ShippedExecutable(pkg, name, target, prefix) for name, (target, prefix) in exes.items()}
        for pkg, exes in entries.items()
    }


SHIPPED: dict[str, dict[str, ShippedExecutable]] = _table()


def shipped_executable(package: str, name: str) -> ShippedExecutable | None:
    """The shipped executable ``name`` of ``package``, or None."""
    return SHIPPED.get(package, {}).get(name)
