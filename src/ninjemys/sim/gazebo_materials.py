"""Gazebo's material scripts as colours: the stock ``Gazebo/*`` names and OGRE ``.material`` files.

No ROS in here. Gazebo colours a visual with ``<material><script><uri>file://media/materials/
scripts/gazebo.material</uri><name>Gazebo/Red</name></script></material>`` (SDF) or
``<gazebo reference="link"><material>Gazebo/Red</material></gazebo>`` (URDF). Gazebo itself is
not installed with us, so its stock names come from :data:`STOCK`, a table written here from the
colours Gazebo's documentation and material gallery give them (the diffuse colour; a textured one by
the colour its picture looks from afar). A material of one's own, in a ``.material`` file a
``<uri>`` names, is read from that file: its first ``diffuse`` (else ``ambient``) colour, else the
mean colour of its first ``texture``. A name found nowhere is the caller's to report once.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

#: Gazebo's stock material names (lower case: Gazebo's lookups ignore case in practice) as 0-255 RGB
STOCK: dict[str, tuple[int, int, int]] = {
    "gazebo/white": (255, 255, 255),
    "gazebo/grey": (179, 179, 179),
    "gazebo/gray": (179, 179, 179),
    "gazebo/lightgrey": (204, 204, 204),
    "gazebo/darkgrey": (45, 45, 45),
    "gazebo/darkgray": (45, 45, 45),
    "gazebo/flatblack": (26, 26, 26),
    "gazebo/black": (0, 0, 0),
    "gazebo/red": (255, 0, 0),
    "gazebo/redbright": (222, 66, 18),
    "gazebo/green": (0, 255, 0),
    "gazebo/blue": (0, 0, 255),
    "gazebo/skyblue": (33, 112, 181),
    "gazebo/yellow": (255, 255, 0),
    "gazebo/zincyellow": (248, 243, 53),
    "gazebo/darkyellow": (179, 179, 0),
    "gazebo/gold": (204, 153, 51),
    "gazebo/purple": (255, 0, 255),
    "gazebo/turquoise": (0, 255, 255),
    "gazebo/orange": (255, 130, 12),
    "gazebo/indigo": (84, 0, 128),
    "gazebo/chrome": (200, 200, 205),
    "gazebo/pioneerbody": (128, 13, 13),
    "gazebo/pioneer2body": (128, 13, 13),
    "gazebo/wood": (156, 112, 74),
    "gazebo/woodfloor": (173, 133, 92),
    "gazebo/woodpallet": (166, 128, 84),
    "gazebo/bricks": (160, 82, 62),
    "gazebo/residential": (196, 186, 170),
    "gazebo/ceilingtiled": (230, 230, 225),
    "gazebo/paintedwall": (235, 230, 220),
    "gazebo/asphalt": (60, 60, 60),
    "gazebo/road": (60, 60, 60),
    "gazebo/motorway": (70, 70, 70),
    "gazebo/footway": (150, 150, 150),
    "gazebo/grass": (80, 140, 50),
    "gazebo/trunk": (100, 70, 40),
    "gazebo/leaf": (60, 120, 40),
}
#: the stock materials that are pictures (a texture): an SDF ``<ambient>``/``<diffuse>`` beside
#: their script tints the picture, it does not replace it (the Building Editor writes
#: ``<ambient>1 1 1 1</ambient>`` beside ``Gazebo/Bricks``, and Gazebo shows bricks)
TEXTURED = frozenset(
    {
        "gazebo/wood",
        "gazebo/woodfloor",
        "gazebo/woodpallet",
        "gazebo/bricks",
        "gazebo/residential",
        "gazebo/ceilingtiled",
        "gazebo/paintedwall",
        "gazebo/asphalt",
        "gazebo/road",
        "gazebo/motorway",
        "gazebo/footway",
        "gazebo/grass",
        "gazebo/trunk",
        "gazebo/leaf",
    }
)
#: the glowing, emissive and see-through variants are drawn in their base colour
_SUFFIXES = ("glow", "emissive", "transparent", "laser")


def stock_colour(name: str) -> tuple[int, int, int] | None:
    """The colour of one of Gazebo's stock materials (``Gazebo/RedGlow`` is red), None if not one."""
    key = name.strip().lower()
    if key in STOCK:
        return STOCK[key]
    for suffix in _SUFFIXES:
        if key.endswith(suffix) and key[: -len(suffix)] in STOCK:
            return STOCK[key[: -len(suffix)]]
    return None


#: ``material NAME`` (optionally ``: PARENT``) opening a block of an OGRE material script
MATERIAL_BLOCK = re.compile(r"^\s*material\s+([^\s{:]+)", re.MULTILINE)
#: a colour or texture line anywhere in a block (one-line blocks too: ``{ pass { diffuse 1 0 0 } }``)
_COLOUR_LINE = re.compile(r"(?<![\w/])(diffuse|ambient)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)")
_TEXTURE_LINE = re.compile(r"(?<![\w/])texture\s+([^\s}]+)")


def material_block(text: str, material: str) -> str | None:
    """The body of ``material``'s block in an OGRE script's text (to the next ``material``), or None."""
    starts = list(MATERIAL_BLOCK.finditer(text))
    for i, block in enumerate(starts):
        if block.group(1) == material:
            return text[block.end() : starts[i + 1].start() if i + 1 < len(starts) else len(text)]
    return None


def script_colour(script_file: Path, material: str) -> tuple[int, int, int] | None:
    """The colour ``material`` has in one ``.material`` file: its diffuse, else its ambient, else
    its texture's mean colour (the texture looked for beside the script and in ``../textures``);
    None when the file does not define it or defines no colour for it."""
    try:
        text = script_file.read_text(errors="replace")
    except OSError:
        return None
    body = material_block(text, material)
    if body is None:
        return None
    found = {m.group(1): m for m in reversed(list(_COLOUR_LINE.finditer(body)))}
    for kind in ("diffuse", "ambient"):
        m = found.get(kind)
        if m is not None:
            try:
                rgb = [min(max(float(m.group(k)), 0.0), 1.0) for k in (2, 3, 4)]
            except ValueError:
                continue
            return (round(rgb[0] * 255), round(rgb[1] * 255), round(rgb[2] * 255))
    texture = _TEXTURE_LINE.search(body)
    if texture is not None:
        for d in (script_file.parent, script_file.parent.parent / "textures"):
            candidate = d / texture.group(1)
            if candidate.is_file():
                return _mean_colour(str(candidate))
    return None


@functools.lru_cache(maxsize=64)
def _mean_colour(path: str) -> tuple[int, int, int] | None:
    """A picture's mean colour, as a textured box looks from a few metres away."""
    import cv2  # a dependency already (cv_bridge); imported where a texture is actually read

    bgr = cv2.imread(path, cv2.IMREAD_COLOR)
    if bgr is None:
        return None
    b, g, r = (round(float(v)) for v in bgr.reshape(-1, 3).mean(axis=0))
    return (r, g, b)
