"""map_server maps: the YAML + image pair, read and written with map_server's semantics.

No ROS in here. :func:`load_map` gives an :class:`OccupancyMap` (int8 cells 0 free / 100 occupied /
-1 unknown, row 0 at the *bottom* like ``nav_msgs/OccupancyGrid.data``) from the same fields
map_server's loader reads (``image``, ``resolution``, ``origin``, ``occupied_thresh``,
``free_thresh``, ``negate``, optional ``mode``): a pixel's occupancy is ``(255 - mean) / 255``
(``mean`` inverted first when ``negate``), above ``occupied_thresh`` occupied, below ``free_thresh``
free, unknown between (``mode: scale`` maps the between-band linearly to 0..100 and ``raw`` takes
the value as is). Images are PGM (P2/P5, 8 or 16 bit) or 8-bit PNG (grey, grey+alpha, RGB, RGBA).
:func:`save_map` writes what ``map_saver`` writes: a P5 PGM (254 free, 0 occupied, 205 unknown) and
its YAML.

Errors name the file and, for YAML, the line: ``office.yaml:3: resolution: expected a number > 0``.
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


class MapFileError(NinjemysError, ValueError):
    """A map or world file that cannot be used; the text names the file, line or field, and why."""


@dataclass
class OccupancyMap:
    """An occupancy grid as ``nav_msgs/OccupancyGrid`` holds it (``data[row, col]``, row 0 at y = origin)."""

    data: np.ndarray  # int8 (height, width): 0 free, 100 occupied, -1 unknown (scale mode: 0..100)
    resolution: float
    origin: tuple[float, float, float]  # x, y, yaw of the cell (0, 0) corner, as map_server's YAML

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def occupied(self, threshold: int = 50) -> np.ndarray:
        """Boolean (height, width): cells at or above ``threshold`` (unknown cells are not obstacles)."""
        return self.data >= threshold


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


def load_map(yaml_path: str | Path) -> OccupancyMap:
    """Read a map_server map (YAML naming its image). Raises MapFileError naming file, line and field."""
    path = Path(yaml_path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise MapFileError(f"{path}: cannot read map: {exc.strerror or exc}") from None
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
    if mode not in ("trinary", "scale", "raw"):
        raise f.error("mode", f"expected trinary, scale or raw, got {mode!r}")
    image_path = Path(image) if Path(image).is_absolute() else path.parent / image
    pixels, alpha = read_image(image_path)
    data = occupancy_from_pixels(pixels, alpha, occ, free, bool(negate), str(mode))
    return OccupancyMap(data, resolution, (origin[0], origin[1], origin[2]))


def occupancy_from_pixels(
    grey: np.ndarray,
    alpha: np.ndarray | None,
    occupied_thresh: float,
    free_thresh: float,
    negate: bool,
    mode: str,
) -> np.ndarray:
    """map_server's per-pixel rule on an image (row 0 at the top); returns OccupancyGrid rows (row 0 at the bottom)."""
    value = grey.astype(np.float64)
    if mode == "raw":
        out = value.astype(np.int16)
        out[out > 100] = -1
        return out[::-1].astype(np.int8).copy()
    if negate:
        value = 255.0 - value
    occ = (255.0 - value) / 255.0
    out = np.full(grey.shape, -1, dtype=np.int8)
    out[occ > occupied_thresh] = 100
    out[occ < free_thresh] = 0
    if mode == "scale":
        between = (occ >= free_thresh) & (occ <= occupied_thresh)
        if occupied_thresh > free_thresh:
            scaled = 99.0 * (occ - free_thresh) / (occupied_thresh - free_thresh)
            out[between] = np.clip(np.rint(scaled[between]), 0, 99).astype(np.int8)
        if alpha is not None:
            out[alpha < 255] = -1
    return out[::-1].copy()


def read_image(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Grey levels 0..255 (uint8, row 0 at the top) and the alpha channel if any, from PGM or PNG."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise MapFileError(f"{path}: cannot read map image: {exc.strerror or exc}") from None
    if raw[:2] in (b"P5", b"P2"):
        return _read_pgm(raw, path), None
    if raw[:8] == b"\x89PNG\r\n\x1a\n":
        return _read_png(raw, path)
    raise MapFileError(f"{path}: unsupported map image (expected PGM P2/P5 or PNG)")


def _read_pgm(raw: bytes, path: Path) -> np.ndarray:
    tokens: list[bytes] = []
    pos = 2
    while len(tokens) < 3:
        while pos < len(raw) and raw[pos : pos + 1].isspace():
            pos += 1
        if pos < len(raw) and raw[pos : pos + 1] == b"#":
            while pos < len(raw) and raw[pos : pos + 1] not in (b"\n", b"\r"):
                pos += 1
            continue
        start = pos
        while pos < len(raw) and not raw[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise MapFileError(f"{path}: truncated PGM header")
        tokens.append(raw[start:pos])
    try:
        width, height, maxval = (int(t) for t in tokens)
    except ValueError:
        raise MapFileError(f"{path}: PGM header is not 'width height maxval'") from None
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise MapFileError(f"{path}: PGM header has width {width}, height {height}, maxval {maxval}")
    count = width * height
    if raw[:2] == b"P5":
        body = raw[pos + 1 :]
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype(np.uint8)
        if len(body) < count * dtype.itemsize:
            raise MapFileError(f"{path}: PGM data is {len(body)} bytes, {count * dtype.itemsize} expected")
        values = np.frombuffer(body, dtype=dtype, count=count).astype(np.float64)
    else:
        try:
            values = np.array(raw[pos:].split()[:count], dtype=np.float64)
        except ValueError:
            raise MapFileError(f"{path}: P2 PGM data holds a non-number") from None
        if values.size < count:
            raise MapFileError(f"{path}: PGM data has {values.size} values, {count} expected")
    grey = np.rint(values * (255.0 / maxval)).astype(np.uint8)
    return grey.reshape(height, width)


def _read_png(raw: bytes, path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    pos = 8
    header = None
    chunks = []
    while pos + 8 <= len(raw):
        length, kind = struct.unpack(">I4s", raw[pos : pos + 8])
        body = raw[pos + 8 : pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            chunks.append(body)
        elif kind == b"IEND":
            break
    if header is None:
        raise MapFileError(f"{path}: PNG without IHDR")
    width, height, depth, colour, _comp, _filt, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise MapFileError(
            f"{path}: PNG must be 8-bit grey/RGB(A), not interlaced (got depth {depth}, colour type {colour})"
        )
    try:
        data = zlib.decompress(b"".join(chunks))
    except zlib.error as exc:
        raise MapFileError(f"{path}: corrupt PNG data: {exc}") from None
    stride = width * channels
    if len(data) < height * (stride + 1):
        raise MapFileError(f"{path}: PNG data is truncated")
    rows = np.frombuffer(data, dtype=np.uint8, count=height * (stride + 1)).reshape(height, stride + 1)
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        kind, line = rows[y, 0], rows[y, 1:].astype(np.int32)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prev) & 0xFF
        else:  # Sub, Average, Paeth depend on the pixel to the left: one pass per pixel
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                left = cur[x - channels] if x >= channels else 0
                up = prev[x]
                upleft = prev[x - channels] if x >= channels else 0
                if kind == 1:
                    pred = left
                elif kind == 3:
                    pred = (left + up) // 2
                else:
                    p = left + up - upleft
                    pa, pb, pc = abs(p - left), abs(p - up), abs(p - upleft)
                    pred = left if pa <= pb and pa <= pc else up if pb <= pc else upleft
                cur[x] = (line[x] + pred) & 0xFF
        out[y] = cur
        prev = cur
    pix = out.reshape(height, width, channels)
    colour_channels = pix[:, :, :3] if channels >= 3 else pix[:, :, :1]
    grey = np.rint(colour_channels.mean(axis=2)).astype(np.uint8)
    alpha = pix[:, :, channels - 1].astype(np.uint8) if channels in (2, 4) else None
    return grey, alpha


def save_map(grid: OccupancyMap, yaml_path: str | Path, image_name: str | None = None) -> Path:
    """Write ``grid`` as map_saver does (P5 PGM + YAML); returns the YAML path."""
    path = Path(yaml_path)
    image = image_name or path.with_suffix(".pgm").name
    pixels = np.full(grid.data.shape, 205, dtype=np.uint8)
    pixels[grid.data == 0] = 254
    pixels[grid.data >= 65] = 0
    body = pixels[::-1].tobytes()
    header = (
        f"P5\n# CREATOR: ninjemys world_to_map {grid.resolution:.3f} m/pix\n{grid.width} {grid.height}\n255\n"
    )
    (path.parent / image).write_bytes(header.encode("ascii") + body)
    ox, oy, oyaw = grid.origin
    path.write_text(
        f"image: {image}\nresolution: {grid.resolution:.6f}\norigin: [{ox:.6f}, {oy:.6f}, {oyaw:.6f}]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        encoding="utf-8",
    )
    return path
