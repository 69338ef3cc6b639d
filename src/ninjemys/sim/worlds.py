"""Where the shipped worlds, maps and robot descriptions are, and how a ``world:=`` argument is resolved."""

from __future__ import annotations

from pathlib import Path

from ninjemys.maps.mapfile import MapFileError
from ninjemys.sim.world2d import World, load_world

#: share/puzzlebot_sim inside the installed package (package.xml, launch/, worlds/, maps/, robots/)
SHARE = Path(__file__).resolve().parent.parent / "packages" / "share" / "puzzlebot_sim"
WORLDS_DIR = SHARE / "worlds"
MAPS_DIR = SHARE / "maps"
ROBOTS_DIR = SHARE / "robots"
SHIPPED_WORLDS = ("empty", "square", "maze", "office")


def world_path(name_or_path: str) -> Path:
    """A shipped world's file for a bare name (``office``), else the path as given."""
    if "/" not in name_or_path and not name_or_path.endswith((".yaml", ".yml")):
        candidate = WORLDS_DIR / f"{name_or_path}.yaml"
        if not candidate.is_file():
            known = ", ".join(sorted(p.stem for p in WORLDS_DIR.glob("*.yaml")))
            raise MapFileError(
                f"world '{name_or_path}': no such shipped world (shipped: {known}; or give a path)"
            )
        return candidate
    return Path(name_or_path).expanduser()


def map_path(name: str) -> Path:
    """The map_server YAML rasterized from shipped world ``name``."""
    return MAPS_DIR / f"{name}.yaml"


def resolve_world(name_or_path: str) -> World:
    return load_world(world_path(name_or_path))
