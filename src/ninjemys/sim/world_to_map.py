"""``rosrun puzzlebot_sim world_to_map WORLD OUT.yaml [--resolution 0.05]``: a world as a map_server map.

Rasterizes a world file (ours, or a map_server map re-sampled) into the YAML + PGM pair that
``map_server`` loads, so the navigation stack uses the very geometry the simulator collides with.
Shipped worlds are named by their name (``office``) or given as a path.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ninjemys.commands import entry
from ninjemys.maps.mapfile import MapFileError, save_map
from ninjemys.sim.world2d import rasterize
from ninjemys.sim.worlds import resolve_world


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="world_to_map", description="Rasterize a simulator world into a map_server map."
    )
    p.add_argument(
        "world", help="a shipped world name (empty, square, maze, office) or a world/map YAML path"
    )
    p.add_argument("output", help="the map YAML to write (the PGM goes next to it)")
    p.add_argument("--resolution", type=float, default=0.05, help="metres per cell (default 0.05)")
    options = p.parse_args(sys.argv[1:] if argv is None else argv)
    if not options.resolution > 0:
        print("world_to_map: --resolution must be > 0", file=sys.stderr)
        return 2
    try:
        world = resolve_world(options.world)
        out = Path(options.output)
        pgm, yml = save_map(rasterize(world, options.resolution), out.with_suffix(""))
    except (MapFileError, OSError) as exc:
        print(f"world_to_map: {exc}", file=sys.stderr)
        return 1
    print(f"wrote {yml} and {pgm.name}")
    return 0


console_main = entry(main)

if __name__ == "__main__":
    console_main()
