"""map_server's loading rules and map_saver's output (ninjemys.maps.mapfile), on small images written here."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from ninjemys.maps.mapfile import GridMap, MapFileError, load_map, map_saver_pixels, save_map


def write_pgm(path: Path, img: np.ndarray) -> None:
    h, w = img.shape
    path.write_bytes(f"P5\n# test\n{w} {h}\n255\n".encode() + img.astype(np.uint8).tobytes())


def write_png(path: Path, img: np.ndarray) -> None:
    h, w, c = img.shape
    colour = {1: 0, 2: 4, 3: 2, 4: 6}[c]
    raw = b"".join(b"\x00" + img[r].astype(np.uint8).tobytes() for r in range(h))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    ihdr = struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    )


def write_yaml(path: Path, image: str, extra: str = "", negate: int = 0, mode: str | None = None) -> Path:
    text = (
        f"image: {image}\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: {negate}\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\n{extra}"
    )
    if mode:
        text += f"mode: {mode}\n"
    path.write_text(text)
    return path


# one row of test pixels: white (free), black (occupied), mid grey (unknown), light grey, 16% grey
ROW = np.array([[255, 0, 128, 220, 214]])


def test_trinary_thresholds_and_row_order(tmp_path):
    img = np.vstack([ROW, np.full((1, 5), 0)])  # top row = ROW, bottom row all black
    write_pgm(tmp_path / "m.pgm", img)
    grid = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm"))
    assert grid.resolution == 0.05 and grid.origin == (-1.0, -2.0, 0.0)
    assert grid.data.shape == (2, 5)
    assert grid.data[0].tolist() == [100] * 5  # the image's last row is the map's row 0
    # occ = (255 - v) / 255: 0 -> free; 1 -> occupied; 0.498 -> unknown; 0.137 -> free; 0.161 -> free
    assert grid.data[1].tolist() == [0, 100, -1, 0, 0]


def test_negate_inverts_pixels(tmp_path):
    write_pgm(tmp_path / "m.pgm", ROW)
    grid = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm", negate=1))
    assert grid.data[0].tolist() == [100, 0, -1, 100, 100]


def test_scale_and_raw_modes(tmp_path):
    write_pgm(tmp_path / "m.pgm", ROW)
    scale = load_map(write_yaml(tmp_path / "s.yaml", "m.pgm", mode="scale")).data[0].tolist()
    occ = (255 - 128) / 255
    assert scale == [0, 100, int(1 + 98 * (occ - 0.196) / (0.65 - 0.196)), 0, 0]
    raw = load_map(write_yaml(tmp_path / "r.yaml", "m.pgm", mode="raw")).data[0]
    assert raw.view(np.uint8).tolist() == [255, 0, 128, 220, 214]


def test_png_rgba_alpha_rules(tmp_path):
    px = np.array([[[128, 128, 128, 0], [128, 128, 128, 255], [0, 0, 0, 255]]])
    write_png(tmp_path / "m.png", px)
    # trinary averages alpha in: (128*3 + 0) / 4 = 96 -> occ 0.62 -> unknown; 160 -> occ 0.37 -> unknown
    assert load_map(write_yaml(tmp_path / "t.yaml", "m.png")).data[0].tolist() == [-1, -1, 100]
    # scale leaves alpha out; a fully transparent pixel between the thresholds is unknown
    scale = load_map(write_yaml(tmp_path / "s.yaml", "m.png", mode="scale")).data[0].tolist()
    assert scale[0] == -1 and 1 <= scale[1] <= 98 and scale[2] == 100


def test_saver_output_reads_back_as_map_server_would(tmp_path):
    data = np.array([[0, 100, -1, 25, 26, 65]], dtype=np.int8)
    pgm, yml = save_map(GridMap(data, 0.1, (1.5, -2.0, 0.25)), tmp_path / "saved")
    assert map_saver_pixels(data).tolist() == [[254, 0, 205, 254, 205, 0]]
    blob = pgm.read_bytes()
    assert blob.startswith(b"P5\n# CREATOR: map_saver.cpp 0.100 m/pix\n6 1\n255\n")
    text = yml.read_text()
    assert "image: saved.pgm\n" in text and "negate: 0\n" in text and "free_thresh: 0.196" in text
    back = load_map(yml)
    assert back.data.tolist() == [[0, 100, -1, 0, -1, 100]]
    assert back.origin == (1.5, -2.0, 0.25) and back.resolution == 0.1


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\nfree_thresh: 0.2\n",
            "occupied_thresh",
        ),
        (
            "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.6\nfree_thresh: 0.2\n",
            "resolution",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0]\nnegate: 0\noccupied_thresh: 0.6\nfree_thresh: 0.2\n",
            "origin",
        ),
        (
            "image: nothere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.6\nfree_thresh: 0.2\n",
            "nothere.pgm",
        ),
        ("image: [unclosed\n", "invalid YAML"),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.6\nfree_thresh: 0.2\nmode: fuzzy\n",
            "mode",
        ),
    ],
)
def test_bad_map_files_name_the_problem(tmp_path, text, needle):
    write_pgm(tmp_path / "m.pgm", ROW)
    (tmp_path / "bad.yaml").write_text(text)
    with pytest.raises(MapFileError) as info:
        load_map(tmp_path / "bad.yaml")
    message = str(info.value)
    assert "bad.yaml" in message and needle in message and "\n" not in message


def test_missing_yaml_and_bad_image(tmp_path):
    with pytest.raises(MapFileError, match="cannot read"):
        load_map(tmp_path / "none.yaml")
    (tmp_path / "m.pgm").write_bytes(b"GIF89a")
    with pytest.raises(MapFileError, match="not a PGM"):
        load_map(write_yaml(tmp_path / "m.yaml", "m.pgm"))
