"""The PuzzleBot world: our YAML format, map_server maps, rasterizing, and the shipped worlds/maps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ninjemys.maps.mapfile import GridMap, MapFileError, load_map, occupancy_from_pixels, save_map
from ninjemys.sim.world2d import load_world, rasterize, world_from_map
from ninjemys.sim.worlds import SHIPPED_WORLDS, map_path, resolve_world


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_map_server_pixel_rule_trinary_negate_scale():
    grey = np.array([[[0], [100], [205], [254]]], dtype=float)  # black, dark grey, map_saver's unknown, free
    assert occupancy_from_pixels(grey, False, False, 0.65, 0.196, "trinary").tolist() == [[100, -1, -1, 0]]
    assert occupancy_from_pixels(grey, False, True, 0.65, 0.196, "trinary").tolist() == [[0, -1, 100, 100]]
    scaled = occupancy_from_pixels(grey, False, False, 0.65, 0.196, "scale")
    assert scaled[0, 0] == 100 and scaled[0, 3] == 0 and 0 <= scaled[0, 1] <= 99


def test_image_rows_are_flipped_like_map_server(tmp_path):
    # top row of the image is the highest y: OccupancyGrid row 0 is the bottom image row
    pgm = b"P5\n2 2\n255\n" + bytes([0, 254, 254, 254])
    (tmp_path / "m.pgm").write_bytes(pgm)
    y = write(
        tmp_path,
        "m.yaml",
        "image: m.pgm\nresolution: 0.5\norigin: [1, 2, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    m = load_map(y)
    assert m.data.tolist() == [[0, 0], [100, 0]]
    assert m.resolution == 0.5 and m.origin == (1.0, 2.0, 0.0)


def test_save_then_load_round_trips(tmp_path):
    data = np.zeros((5, 7), dtype=np.int8)
    data[1, 2] = 100
    data[4, 6] = -1
    save_map(GridMap(data, 0.1, (-1.0, -2.0, 0.0)), tmp_path / "x")
    m = load_map(tmp_path / "x.yaml")
    assert np.array_equal(m.data, data) and m.origin == (-1.0, -2.0, 0.0)


def test_png_map(tmp_path):
    import zlib

    def chunk(kind, body):
        import struct

        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    import struct

    rows = b"\x00" + bytes([0, 255, 255]) + b"\x02" + bytes([0, 0, 0])  # Up filter on row 2
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 3, 2, 8, 0, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    (tmp_path / "p.png").write_bytes(png)
    y = write(
        tmp_path,
        "p.yaml",
        "image: p.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    assert load_map(y).data.tolist() == [[100, 0, 0], [100, 0, 0]]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "m.yaml:2: resolution: expected a number > 0",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "m.yaml:3: origin: expected a list of 3 numbers",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n",
            "missing field 'free_thresh'",
        ),
        ("image: m.pgm\nresolution: [0.05\n", "m.yaml:3: invalid YAML"),
        (
            "image: nope.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "nope.pgm: cannot read map image",
        ),
    ],
)
def test_malformed_map_names_file_line_field(tmp_path, text, expected):
    (tmp_path / "m.pgm").write_bytes(b"P5\n1 1\n255\n\x00")
    with pytest.raises(MapFileError, match=expected.replace("[", r"\[")):
        load_map(write(tmp_path, "m.yaml", text))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "walls:\n  - {from: [0, 0], to: [1, 0], height: -2}\n",
            "w.yaml:2: walls[0].height: expected a number > 0, got -2",
        ),
        (
            "walls:\n  - {from: [0, 0], to: [1, 0]}\n  - {from: [0, 0]}\n",
            "w.yaml:3: walls[1]: missing field 'to'",
        ),
        (
            "boxes:\n  - center: [0, 0]\n    size: [1, 1]\n    colour: red\n",
            "w.yaml:4: boxes[0].colour: unknown field",
        ),
        (
            "cylinders:\n  - {center: [0, 0], radius: 0.2, color: mauve}\n",
            "w.yaml:2: cylinders[0].color: unknown colour 'mauve'",
        ),
        ("robots:\n  - {name: 'a b', pose: [0, 0, 0]}\n", "w.yaml:2: robots[0].name: expected a ROS name"),
        ("walls: [\n", "w.yaml:2: invalid YAML"),
        (
            "moving:\n  - {waypoints: [[0, 0], [1]]}\n",
            "w.yaml:2: moving[0].waypoints[1]: expected a list of 2 numbers",
        ),
    ],
)
def test_malformed_world_names_file_line_field(tmp_path, text, expected):
    with pytest.raises(MapFileError, match=expected.replace("[", r"\[")):
        load_world(write(tmp_path, "w.yaml", text))


def test_world_shapes_become_segments_with_heights_and_colours(tmp_path):
    w = load_world(
        write(
            tmp_path,
            "w.yaml",
            "walls:\n  - {from: [0, 0], to: [2, 0], thickness: 0, height: 0.3, color: '#ff0000'}\n"
            "boxes:\n  - {center: [5, 5], size: [1, 2], height: 0.7}\n"
            "cylinders:\n  - {center: [-3, 0], radius: 0.5, color: [1, 2, 3]}\n"
            "robots:\n  - {name: r1, pose: [1, 1, 0.5]}\n  - {name: r2}\n",
        )
    )
    assert len(w.segments) == 1 + 4 + 24
    assert w.seg_height[0] == 0.3 and tuple(w.seg_color[0]) == (255, 0, 0)
    assert tuple(w.seg_color[-1]) == (1, 2, 3)
    assert [r.name for r in w.robots] == ["r1", "r2"] and w.robots[0].yaw == 0.5


def test_moving_obstacle_follows_waypoints(tmp_path):
    w = load_world(
        write(tmp_path, "w.yaml", "moving:\n  - {waypoints: [[0, 0], [2, 0]], speed: 1, loop: false}\n")
    )
    m = w.moving[0]
    assert m.position(0.5)[:2] == pytest.approx((0.5, 0.0))
    assert m.position(3.0)[:2] == pytest.approx((1.0, 0.0))  # on the way back


def test_rasterize_keeps_thin_walls_solid(tmp_path):
    w = load_world(
        write(
            tmp_path,
            "w.yaml",
            "bounds: [0, 0, 2, 2]\nwalls:\n  - {from: [1.01, 0], to: [1.01, 2], thickness: 0}\n",
        )
    )
    m = rasterize(w, 0.1)
    assert m.data.shape == (20, 20)
    assert (m.data[:, 10] == 100).all() and (m.data[:, :10] == 0).all()


@pytest.mark.parametrize("name", SHIPPED_WORLDS)
def test_shipped_worlds_load_and_their_maps_are_their_rasterization(name):
    world = resolve_world(name)
    shipped = load_map(map_path(name))
    assert np.array_equal(shipped.data, rasterize(world, shipped.resolution).data)
    # the robot's start in every shipped world is free
    r = world.robots[0]
    col = int((r.x - shipped.origin[0]) / shipped.resolution)
    row = int((r.y - shipped.origin[1]) / shipped.resolution)
    assert shipped.data[row, col] == 0


def test_map_as_world(tmp_path):
    w = world_from_map(map_path("maze"))
    assert w.grid is not None and w.grid.occupied.any()
    with pytest.raises(MapFileError, match="no such shipped world"):
        resolve_world("atlantis")


def test_world_to_map_command(tmp_path, capsys):
    from ninjemys.sim.world_to_map import main

    assert main(["maze", str(tmp_path / "m.yaml"), "--resolution", "0.1"]) == 0
    assert load_map(tmp_path / "m.yaml").resolution == pytest.approx(0.1)
    assert main(["atlantis", str(tmp_path / "x.yaml")]) == 1
    assert "no such shipped world" in capsys.readouterr().err
