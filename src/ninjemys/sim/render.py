"""Turn the world into pictures: a composed RGB frame (path image + turtles) and PNG bytes.

Pure numpy + zlib, so the node can serve ``/turtlesim/snapshot.png`` and tests can check pixels
without a browser.
"""

from __future__ import annotations

import math
import struct
import zlib

import numpy as np

from ninjemys.sim.world import Pen, World, draw_line

#: Turtle body colour in snapshots (the browser view draws its own turtle shape).
TURTLE_SHELL = (46, 139, 87)
TURTLE_HEAD = (255, 200, 120)
#: Body radius in pixels (ROS's turtle images are 45 px across).
TURTLE_RADIUS = 12.0


def compose_frame(world: World) -> np.ndarray:
    """The path image with every turtle drawn on top: what the turtlesim window shows."""
    frame = world.image.copy()
    for turtle in world.turtles.values():
        col, row = world.to_pixel(turtle.x, turtle.y)
        shell = Pen(*TURTLE_SHELL, width=int(TURTLE_RADIUS * 2))
        draw_line(frame, (col, row), (col, row), shell)
        head_col = col + math.cos(turtle.theta) * TURTLE_RADIUS
        head_row = row - math.sin(turtle.theta) * TURTLE_RADIUS
        draw_line(frame, (head_col, head_row), (head_col, head_row), Pen(*TURTLE_HEAD, width=10))
    return frame


def png_bytes(image: np.ndarray) -> bytes:
    """Encode an (H, W, 3) uint8 array as a PNG (filter 0 on every row, zlib level 6)."""
    height, width = image.shape[:2]
    rows = np.zeros((height, width * 3 + 1), dtype=np.uint8)
    rows[:, 1:] = np.ascontiguousarray(image, dtype=np.uint8).reshape(height, width * 3)

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
        + chunk(b"IEND", b"")
    )
