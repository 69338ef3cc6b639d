"""map_server's map files: the YAML + image pair, loaded and saved with map_server's exact rules.

No ROS in here. :func:`load_map` reads what ``map_server`` reads (``image``, ``resolution``,
``origin``, ``negate``, ``occupied_thresh``, ``free_thresh``, optional ``mode``) and gives the cells
as ``nav_msgs/OccupancyGrid.data`` holds them (row 0 at the bottom, the image's last row):

- a pixel's value is the mean of its colour channels (alpha excluded, except that ``scale`` mode
  makes a fully transparent pixel unknown), inverted (``255 - v``) when ``negate``;
- ``raw`` mode stores that value as is;
- otherwise ``occ = (255 - v) / 255``: above ``occupied_thresh`` is 100, below ``free_thresh`` is 0,
  between is -1 (``trinary``, the default) or ``1 + 98 * ratio`` truncated (``scale``).

:func:`save_map` writes what ``map_saver`` writes: a P5 PGM (254 free for 0..``free``, 0 occupied for
``occ``..100, 205 otherwise, first image row = top of the map) and a YAML with ``negate: 0``,
``occupied_thresh: 0.65``, ``free_thresh: 0.196``.

Every error is a :class:`MapError` whose text names the file and the field or line.
"""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from ninjemys.errors import NinjemysError

MODES = ("trinary", "scale", "raw")


class MapError(NinjemysError, ValueError):
    """A map file that cannot be used; the text says which file, which field and why."""


@dataclass
class GridMap:
    """An occupancy grid as ``nav_msgs/OccupancyGrid``: ``data[row, col]``, row 0 at ``origin``'s y."""

    data: np.ndarray  # int8 (height, width)
    resolution: float
    origin: tuple[float, float, float]  # x, y, yaw of the corner of cell (0, 0)

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """(col, row) of the cell holding world point (x, y) (the map's yaw is taken as 0, like amcl)."""
        return (
            int(math.floor((x - self.origin[0]) / self.resolution)),
            int(math.floor((y - self.origin[1]) / self.resolution)),
        )

    def cell_to_world(self, col: float, row: float) -> tuple[float, float]:
        """World (x, y) of the centre of cell (col, row)."""
        return (
            self.origin[0] + (col + 0.5) * self.resolution,
            self.origin[1] + (row + 0.5) * self.resolution,
        )

    def inside(self, col: int, row: int) -> bool:
        return 0 <= col < self.width and 0 <= row < self.height


# -- images -------------------------------------------------------------------------------------------


def _pgm_tokens(blob: bytes, count: int) -> tuple[list[int], int]:
    """The first ``count`` header integers of a PNM file and the offset just past the last one."""
    values: list[int] = []
    pos = 2
    while len(values) < count:
        while pos < len(blob) and blob[pos : pos + 1].isspace():
            pos += 1
        if blob[pos : pos + 1] == b"#":
            while pos < len(blob) and blob[pos] not in (10, 13):
                pos += 1
            continue
        start = pos
        while pos < len(blob) and blob[pos : pos + 1].isdigit():
            pos += 1
        if start == pos:
            raise ValueError("truncated or malformed PNM header")
        values.append(int(blob[start:pos]))
    return values, pos


def _read_pnm(blob: bytes) -> np.ndarray:
    magic = blob[:2]
    channels = {b"P2": 1, b"P5": 1, b"P3": 3, b"P6": 3}.get(magic)
    if channels is None:
        raise ValueError(f"not a PGM/PPM image (magic {magic!r})")
    (width, height, maxval), pos = _pgm_tokens(blob, 3)
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise ValueError(f"bad PNM size {width}x{height} maxval {maxval}")
    count = width * height * channels
    if magic in (b"P2", b"P3"):
        values = np.array(blob[pos:].split(), dtype=np.int64)[:count]
    else:
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        raw = blob[pos + 1 : pos + 1 + count * dtype.itemsize]
        values = np.frombuffer(raw, dtype=dtype)
    if values.size != count:
        raise ValueError(f"image data truncated: {values.size} of {count} samples")
    values = values.astype(np.float64)
    if maxval != 255:
        values = np.floor(values * 255.0 / maxval)
    return values.reshape(height, width, channels)


def _read_png(blob: bytes) -> np.ndarray:
    pos = 8
    idat = bytearray()
    header = None
    while pos + 8 <= len(blob):
        (length,) = struct.unpack(">I", blob[pos : pos + 4])
        kind = blob[pos + 4 : pos + 8]
        body = blob[pos + 8 : pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    if header is None:
        raise ValueError("PNG without IHDR")
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError(
            f"PNG with bit depth {depth}, colour type {colour}, interlace {interlace} is not supported"
        )
    raw = np.frombuffer(zlib.decompress(bytes(idat)), dtype=np.uint8)
    stride = width * channels
    rows = raw.reshape(height, stride + 1)
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for r in range(height):
        kind, line = int(rows[r, 0]), rows[r, 1:].astype(np.int32)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prev) & 255
        else:
            cur = np.zeros(stride, dtype=np.int32)
            for i in range(stride):
                left = int(cur[i - channels]) if i >= channels else 0
                up = int(prev[i])
                ul = int(prev[i - channels]) if i >= channels else 0
                if kind == 1:
                    pred = left
                elif kind == 3:
                    pred = (left + up) // 2
                else:
                    p = left + up - ul
                    pa, pb, pc = abs(p - left), abs(p - up), abs(p - ul)
                    pred = left if pa <= pb and pa <= pc else up if pb <= pc else ul
                cur[i] = (int(line[i]) + pred) & 255
        out[r] = cur
        prev = cur
    return out.reshape(height, width, channels).astype(np.float64)


def read_image(path: Path) -> tuple[np.ndarray, bool]:
    """(pixels as float (height, width, channels), has_alpha) of a PGM/PPM or 8-bit PNG file."""
    blob = path.read_bytes()
    if blob[:8] == b"\x89PNG\r\n\x1a\n":
        pixels = _read_png(blob)
        return pixels, pixels.shape[2] in (2, 4)
    return _read_pnm(blob), False


# -- loading ------------------------------------------------------------------------------------------


def occupancy_from_pixels(
    pixels: np.ndarray,
    has_alpha: bool,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
    mode: str = "trinary",
) -> np.ndarray:
    """map_server's pixel rule over a whole image; returns int8 cells with row 0 at the image's bottom."""
    channels = pixels.shape[2]
    # map_server averages the alpha channel in too in trinary mode, and leaves it out otherwise
    colour = pixels[:, :, : channels - 1] if (has_alpha and mode != "trinary") else pixels
    avg = colour.sum(axis=2) / colour.shape[2]
    if negate:
        avg = 255.0 - avg
    if mode == "raw":
        cells = avg.astype(np.int64).astype(np.int8)
    else:
        occ = (255.0 - avg) / 255.0
        cells = np.full(avg.shape, -1, dtype=np.int8)
        cells[occ > occupied_thresh] = 100
        cells[occ < free_thresh] = 0
        if mode == "scale":
            between = (occ <= occupied_thresh) & (occ >= free_thresh)
            if has_alpha:
                between &= pixels[:, :, channels - 1] >= 1.0
            ratio = (occ - free_thresh) / (occupied_thresh - free_thresh)
            cells[between] = (1 + 98 * ratio[between]).astype(np.int8)
    return np.ascontiguousarray(cells[::-1])


def _field(doc: dict, key: str, path: Path, kind: type, default: object = None) -> object:
    if key not in doc:
        if default is not None:
            return default
        raise MapError(f"{path}: the map YAML has no '{key}' field")
    value = doc[key]
    try:
        if kind is float:
            if isinstance(value, bool):
                raise TypeError
            return float(value)
        if kind is bool:
            if isinstance(value, str):
                raise TypeError
            return bool(int(value))
    except (TypeError, ValueError):
        raise MapError(f"{path}: '{key}' must be a {kind.__name__}, got {value!r}") from None
    return value


def load_map(yaml_path: str | Path) -> GridMap:
    """Load ``yaml_path`` and its image as map_server does; raise :class:`MapError` naming the problem."""
    path = Path(yaml_path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise MapError(f"{path}: cannot read the map YAML: {exc.strerror or exc}") from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        raise MapError(f"{where}: the map YAML does not parse: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path}: the map YAML must be a mapping of fields")
    resolution = _field(doc, "resolution", path, float)
    if not resolution > 0:  # type: ignore[operator]
        raise MapError(f"{path}: 'resolution' must be > 0, got {resolution}")
    origin = doc.get("origin")
    if not isinstance(origin, list) or len(origin) != 3:
        raise MapError(f"{path}: 'origin' must be a list [x, y, yaw], got {origin!r}")
    try:
        origin_t = (float(origin[0]), float(origin[1]), float(origin[2]))
    except (TypeError, ValueError):
        raise MapError(f"{path}: 'origin' must hold three numbers, got {origin!r}") from None
    negate = _field(doc, "negate", path, bool)
    occ = _field(doc, "occupied_thresh", path, float)
    free = _field(doc, "free_thresh", path, float)
    mode = str(doc.get("mode", "trinary"))
    if mode not in MODES:
        raise MapError(f"{path}: 'mode' must be one of {', '.join(MODES)}, got {mode!r}")
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise MapError(f"{path}: the map YAML has no 'image' field")
    image_path = Path(image) if Path(image).is_absolute() else path.parent / image
    try:
        pixels, alpha = read_image(image_path)
    except OSError as exc:
        raise MapError(f"{path}: image {image_path}: {exc.strerror or exc}") from None
    except (ValueError, zlib.error) as exc:
        raise MapError(f"{path}: image {image_path}: {exc}") from None
    cells = occupancy_from_pixels(pixels, alpha, bool(negate), occ, free, mode)  # type: ignore[arg-type]
    return GridMap(cells, float(resolution), origin_t)  # type: ignore[arg-type]


# -- saving -------------------------------------------------------------------------------------------


def map_saver_pixels(data: np.ndarray, occupied: int = 65, free: int = 25) -> np.ndarray:
    """map_saver's trinary image (top row first): 254 free, 0 occupied, 205 unknown."""
    cells = np.asarray(data, dtype=np.int16)
    img = np.full(cells.shape, 205, dtype=np.uint8)
    img[(cells >= 0) & (cells <= free)] = 254
    img[cells >= occupied] = 0
    return np.ascontiguousarray(img[::-1])


def save_map(grid: GridMap, base: str | Path, occupied: int = 65, free: int = 25) -> tuple[Path, Path]:
    """Write ``base.pgm`` and ``base.yaml`` as ``map_saver -f base`` does; return both paths."""
    base = Path(base)
    pgm = base.with_name(base.name + ".pgm")
    yml = base.with_name(base.name + ".yaml")
    img = map_saver_pixels(grid.data, occupied, free)
    header = f"P5\n# CREATOR: map_saver.cpp {grid.resolution:.3f} m/pix\n{grid.width} {grid.height}\n255\n"
    pgm.write_bytes(header.encode() + img.tobytes())
    x, y, yaw = grid.origin
    yml.write_text(
        f"image: {pgm.name}\nresolution: {grid.resolution:f}\norigin: [{x:f}, {y:f}, {yaw:f}]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n\n"
    )
    return pgm, yml
