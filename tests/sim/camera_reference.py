"""The camera image drawn the slow, obvious way, pixel by pixel: what the fast renderer
(:mod:`ninjemys.sim.camera`) must agree with, in the tests that compare them."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np

from ninjemys.sim.camera import FLOOR_RGB, SKY_RGB
from ninjemys.sim.simcore import Simulation


def ray_hits(x: float, y: float, angle: float, segs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distances along one ray to every segment it crosses, nearest first, and those segments."""
    dx, dy = math.cos(angle), math.sin(angle)
    ex, ey = segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]
    px, py = segs[:, 0] - x, segs[:, 1] - y
    den = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (px * ey - py * ex) / den
        s = (px * dy - py * dx) / den
    ok = (den != 0) & (t > 0) & (s >= 0) & (s <= 1)
    idx = np.flatnonzero(ok)
    order = np.argsort(t[idx], kind="stable")
    return t[idx][order], idx[order]


def reference_render(sim: Simulation, r: Any) -> tuple[np.ndarray, np.ndarray]:
    """Every obstacle is a prism, its outline extruded from its base to its top. For each pixel, the
    nearest point where the pixel's ray meets one: a side (between base and top where the ray
    enters the outline), the lid (a shape lower than the camera, seen from above) or the underside
    (a shape held above the camera); else floor below the horizon, else sky. Colour: the obstacle's,
    flat, darker with the depth of the side the ray crosses in that column (for a lid or an
    underside: the side where the ray leaves the outline). Only sides within the depth range count."""
    cam = r.camera
    spec = r.model.camera
    x, y = sim.sensor_pose(r, spec.pose.xyz)
    yaw = r.yaw + spec.pose.rpy[2]
    far = cam.depth_max / float(cam.col_cos.min())
    rgb = np.zeros((cam.height, cam.width, 3), dtype=np.uint8)
    depth = np.zeros((cam.height, cam.width), dtype=np.uint16)
    pieces: list[tuple[Any, np.ndarray]] = [(ob, ob.segments()) for ob in sim.world.obstacles]
    for i, m in enumerate(sim.world.moving):  # moving obstacles (people) where they are now
        pieces.append(
            (
                SimpleNamespace(base=0.0, height=m.height, color=m.color),
                sim._mover_outline(i, *m.position(sim.world_time)),
            )
        )
    for u in range(cam.width):
        angle = yaw + cam.col_angles[u]
        spans = []  # (entry depth, exit depth, obstacle)
        for ob, segs in pieces:
            dists, _ = ray_hits(x, y, angle, segs)
            depths = dists[dists <= far] * cam.col_cos[u]
            if len(segs) == 1:  # a thin wall: no inside
                spans += [(d, d, ob) for d in depths]
            else:  # a closed outline: entering and leaving in turn
                spans += [(depths[i], depths[i + 1], ob) for i in range(0, len(depths) - 1, 2)]
        for v in range(cam.height):
            slope = cam.row_slope[v]
            best: tuple[float, float, Any] | None = None  # (hit depth, shading depth, obstacle)
            for d_in, d_out, ob in spans:
                z_in = cam.cam_z + slope * d_in
                hit = None
                if ob.base - 1e-12 <= z_in <= ob.height + 1e-12 and d_in <= cam.depth_max:
                    hit = (d_in, d_in)
                elif z_in > ob.height and slope < 0 and d_out <= cam.depth_max:
                    d = (ob.height - cam.cam_z) / slope
                    hit = (d, d_out) if d <= d_out else None
                elif z_in < ob.base and slope > 0 and d_out <= cam.depth_max:
                    d = (ob.base - cam.cam_z) / slope
                    hit = (d, d_out) if d <= d_out else None
                if hit is not None and (best is None or hit[0] < best[0]):
                    best = (hit[0], hit[1], ob)
            if best is not None:
                d, shade_d, ob = best
                light = min(max(1.1 - shade_d / 15.0, 0.45), 1.0)
                rgb[v, u] = (np.array(ob.color, dtype=np.float32) * light).astype(np.uint8)
                depth[v, u] = round(d * 1000.0)
            elif slope < -1e-9:
                floor = cam.cam_z / -slope
                floor = floor if floor <= cam.depth_max else 0.0  # beyond the depth range: no data
                shade = min(max(1.15 - floor / 12.0, 0.55), 1.0)
                rgb[v, u] = (shade * FLOOR_RGB).astype(np.uint8)
                depth[v, u] = round(floor * 1000.0)
            else:
                rgb[v, u] = SKY_RGB.astype(np.uint8)
    return rgb, depth


def assert_matches_reference(sim: Simulation, r: Any) -> None:
    """Colour and depth pixel by pixel (a pixel on a side's exact top, base or foot row may go either
    way in floating point: at most two such rows per column, one at each end)."""
    rgb, depth = sim.render(r)
    ref_rgb, ref_depth = reference_render(sim, r)
    assert rgb.shape == ref_rgb.shape and depth.dtype == np.uint16
    rgb_off = (rgb != ref_rgb).any(axis=2).sum(axis=0)
    # a lid's depth is rounded to whole millimetres from two slightly different formulas
    depth_off = (np.abs(depth.astype(int) - ref_depth) > 1).sum(axis=0)
    assert rgb_off.max() <= 2 and depth_off.max() <= 2, (np.flatnonzero(rgb_off > 2), rgb_off.max())
    assert rgb_off.sum() < 20 and depth_off.sum() < 20, (rgb_off.sum(), depth_off.sum())
