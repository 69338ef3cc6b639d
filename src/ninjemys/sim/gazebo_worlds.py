"""Which world a Gazebo ``world_name`` means: ``.world`` files found as Gazebo finds them.

A path that exists is that file; a relative name (``worlds/empty.world``, as empty_world.launch
passes it) is looked up in ``GAZEBO_RESOURCE_PATH`` and then in our gazebo_ros share directory.
The SDF itself is read by :mod:`ninjemys.sim.sdf` (``load_sdf_world``); Gazebo's empty world is
known here too, so ``empty_world.launch`` runs even where that reader is absent.
"""

from __future__ import annotations

import importlib
import os
from pathlib import Path

from ninjemys.maps.mapfile import MapFileError
from ninjemys.sim.world2d import World

GAZEBO_ROS_SHARE = Path(__file__).resolve().parent.parent / "packages" / "share" / "gazebo_ros"
EMPTY_WORLD = GAZEBO_ROS_SHARE / "worlds" / "empty.world"


def find_world(name: str, env: dict[str, str] | None = None) -> Path:
    """The .world file ``name`` stands for (MapFileError naming where it looked when none)."""
    path = Path(name).expanduser()
    if path.is_file():
        return path.resolve()
    environ = os.environ if env is None else env
    dirs = [Path(d) for d in environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if d]
    if not path.is_absolute():
        for d in [*dirs, GAZEBO_ROS_SHARE]:
            if (d / path).is_file():
                return (d / path).resolve()
    looked = ", ".join(str(d) for d in [*dirs, GAZEBO_ROS_SHARE]) or "nowhere"
    raise MapFileError(
        f"world file [{name}] not found (looked in the current directory and in {looked}; "
        "set GAZEBO_RESOURCE_PATH or give a path)"
    )


def load_gazebo_world(name: str) -> World:
    """The simulator's World for a Gazebo ``world_name``."""
    path = find_world(name)
    try:
        sdf = importlib.import_module("ninjemys.sim.sdf")
    except ModuleNotFoundError:
        sdf = None
    if sdf is not None and hasattr(sdf, "load_sdf_world"):
        world: World = sdf.load_sdf_world(path)
        return world
    if path == EMPTY_WORLD.resolve():
        return World("default", bounds=(-5.0, -5.0, 5.0, 5.0), source=str(path))
    raise MapFileError(
        f"{path}: this build reads no SDF worlds other than worlds/empty.world (ninjemys.sim.sdf is missing)"
    )
