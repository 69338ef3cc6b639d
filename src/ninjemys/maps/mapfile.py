"""map_server maps: the YAML + image pair, read as ``map_server`` reads it and written as ``map_saver``
writes it; and the line-aware YAML reading that the simulator's world and robot files share.

No ROS in here. The simulator (worlds made from maps, ``world_to_map``) and the navigation stack
(``map_server``, ``map_saver``, amcl, slam_gmapping, the costmaps) both use this one module.

:func:`load_map` reads the fields map_server reads (``image``, ``resolution``, ``origin``, ``negate``,
``occupied_thresh``, ``free_thresh``, optional ``mode``) and gives a :class:`GridMap` whose cells are
what ``nav_msgs/OccupancyGrid.data`` holds (row 0 at the bottom, the image's last row), by map_server's
exact rules:

- a pixel's value is the mean of its channels; in ``trinary`` mode the alpha channel is averaged in
  too, in the other modes it is left out (and ``scale`` makes a fully transparent pixel unknown);
  ``negate`` inverts it (``255 - v``);
- ``raw`` mode stores that value as is (an int8, as map_server's assignment wraps it);
- otherwise ``occ = (255 - v) / 255``: above ``occupied_thresh`` is 100, below ``free_thresh`` is 0,
  between is -1 (``trinary``, the default) or ``1 + 98 * ratio`` truncated (``scale``).

Images are PGM/PPM (P2/P3/P5/P6, 8 or 16 bit) or 8-bit PNG (grey, grey+alpha, RGB, RGBA).
:func:`save_map` writes what ``map_saver`` writes: a P5 PGM (254 free for 0..``free``, 0 occupied for
``occ``..100, 205 otherwise, first image row = top of the map) and a YAML with ``negate: 0``,
``occupied_thresh: 0.65``, ``free_thresh: 0.196``.

Every error is a :class:`MapFileError` naming the file and, for YAML, the line and field:
``office.yaml:3: resolution: expected a number > 0, got -1``.
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


class MapFileError(NinjemysError, ValueError):
    """A map or world file that cannot be used; the text names the file, line or field, and why."""


@dataclass
class GridMap:
    """An occupancy grid as ``nav_msgs/OccupancyGrid``: ``data[row, col]``, row 0 at ``origin``'s y."""

    data: np.ndarray  # int8 (height, width): 0 free, 100 occupied, -1 unknown (scale mode: 0..100)
    resolution: float
    origin: tuple[float, float, float]  # x, y, yaw of the corner of cell (0, 0), as map_server's YAML

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def occupied(self, threshold: int = 50) -> np.ndarray:
        """Boolean (height, width): cells at or above ``threshold`` (unknown cells are not obstacles)."""
        return self.data >= threshold

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


# -- YAML with lines ----------------------------------------------------------------------------------


def yaml_lines(text: str, path: str) -> tuple[object, dict[str, int]]:
    """Parse YAML keeping the line of every value: (data, {"walls[2].height": 14, ...}).

    Syntax errors become ``MapFileError("file:line: reason")``.
    """
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise MapFileError(f"{path}{line}: invalid YAML: {problem}") from None
    lines: dict[str, int] = {}
    if node is None:
        return None, lines
    constructor = yaml.SafeLoader("")

    def build(n: yaml.Node, where: str) -> object:
        lines[where] = n.start_mark.line + 1
        if isinstance(n, yaml.MappingNode):
            out: dict[str, object] = {}
            for k, v in n.value:
                key = str(constructor.construct_object(k, deep=True))
                out[key] = build(v, f"{where}.{key}" if where else key)
            return out
        if isinstance(n, yaml.SequenceNode):
            return [build(v, f"{where}[{i}]") for i, v in enumerate(n.value)]
        return constructor.construct_object(n, deep=True)

    try:
        return build(node, ""), lines
    except yaml.YAMLError as exc:
        raise MapFileError(f"{path}: invalid YAML: {exc}") from None


class Fields:
    """Typed access to a parsed YAML mapping with errors that say ``file:line: field: reason``."""

    def __init__(self, path: str, lines: dict[str, int]) -> None:
        self.path = path
        self.lines = lines

    def error(self, where: str, reason: str) -> MapFileError:
        probe = where
        while probe and probe not in self.lines:
            probe = (
                probe.rsplit(".", 1)[0] if "." in probe else probe.rsplit("[", 1)[0] if "[" in probe else ""
            )
        line = self.lines.get(probe)
        loc = f"{self.path}:{line}" if line else self.path
        return MapFileError(f"{loc}: {where}: {reason}" if where else f"{loc}: {reason}")

    def number(
        self, value: object, where: str, minimum: float | None = None, positive: bool = False
    ) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(where, f"expected a number, got {value!r}")
        out = float(value)
        if not math.isfinite(out):
            raise self.error(where, f"expected a finite number, got {value!r}")
        if positive and out <= 0:
            raise self.error(where, f"expected a number > 0, got {value!r}")
        if minimum is not None and out < minimum:
            raise self.error(where, f"expected a number >= {minimum:g}, got {value!r}")
        return out

    def vector(self, value: object, where: str, size: int) -> list[float]:
        if not isinstance(value, list) or len(value) != size:
            raise self.error(where, f"expected a list of {size} numbers, got {value!r}")
        return [self.number(v, f"{where}[{i}]") for i, v in enumerate(value)]


def text_byte(exc: UnicodeDecodeError) -> int:
    """The byte a UTF-8 decode stopped at (for messages that say where a file is not text)."""
    return exc.object[exc.start]


def load_map(yaml_path: str | Path) -> GridMap:
    """Read a map_server map (YAML naming its image). Raises MapFileError naming file, line and field."""
    path = Path(yaml_path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise MapFileError(f"{path}: cannot read map: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise MapFileError(
            f"{path}: not a text (UTF-8) file: byte {exc.start} is 0x{text_byte(exc):02x}"
        ) from None
    doc, lines = yaml_lines(text, str(path))
    f = Fields(str(path), lines)
    if not isinstance(doc, dict):
        raise f.error("", "a map_server map YAML must be a mapping with image, resolution, origin, ...")
    for key in ("image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate"):
        if key not in doc:
            raise f.error("", f"missing field '{key}' (map_server needs it)")
    image = doc["image"]
    if not isinstance(image, str) or not image:
        raise f.error("image", f"expected a file name, got {image!r}")
    resolution = f.number(doc["resolution"], "resolution", positive=True)
    origin = f.vector(doc["origin"], "origin", 3)
    occ = f.number(doc["occupied_thresh"], "occupied_thresh")
    free = f.number(doc["free_thresh"], "free_thresh")
    if not 0.0 <= free <= occ <= 1.0:
        raise f.error("free_thresh", f"need 0 <= free_thresh ({free:g}) <= occupied_thresh ({occ:g}) <= 1")
    negate = doc["negate"]
    if negate not in (0, 1, True, False):
        raise f.error("negate", f"expected 0 or 1, got {negate!r}")
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise f.error("mode", f"expected trinary, scale or raw, got {mode!r}")
    image_path = Path(image) if Path(image).is_absolute() else path.parent / image
    try:
        pixels, alpha = read_image(image_path)
    except OSError as exc:
        raise MapFileError(
            f"{path}: image {image_path}: cannot read map image: {exc.strerror or exc}"
        ) from None
    except (ValueError, zlib.error) as exc:
        raise MapFileError(f"{path}: image {image_path}: {exc}") from None
    cells = occupancy_from_pixels(pixels, alpha, bool(negate), occ, free, str(mode))
    return GridMap(cells, resolution, (origin[0], origin[1], origin[2]))


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
        raise ValueError(f"not a PGM/PPM or PNG image (magic {magic!r})")
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


# -- the pixel rule ---------------------------------------------------------------------------------


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
