"""The camera image drawn the slow, obvious way, pixel by pixel: what the fast renderer
(:mod:`ninjemys.sim.camera`) must agree with, in the tests that compare them."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np

from ninjemys.sim.camera import FLOOR_RGB, SKY_RGB
from ninjemys.sim.lighting import Lighting
from ninjemys.sim.simcore import Simulation


def lit(colour: Any, normal: tuple[float, float, float], lighting: Lighting) -> np.ndarray:
    """Gazebo's rule, written out for one pixel: colour x (ambient + sum of diffuse x max(0, n . -d))."""
    factor = np.array(lighting.ambient, dtype=float)
    for sun in lighting.suns:
        d = np.array(sun.direction, dtype=float)
        factor = factor + np.array(sun.diffuse) * max(0.0, float(np.dot(normal, -d / np.linalg.norm(d))))
    value = np.array(colour, dtype=float) * factor
    return np.clip(np.floor(value + 0.5), 0, 255).astype(np.uint8)


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
    lit by the world's lights (:func:`lit`) on the normal of what the ray meets: a side's, turned
    toward the camera (a round shape's from its axis; a sphere's tilted by the height it is met at),
    a lid's up, an underside's down; the floor's up. Only sides within the depth range count."""
    cam = r.camera
    spec = r.model.camera
    x, y = sim.sensor_pose(r, spec.pose.xyz)
    yaw = r.yaw + spec.pose.rpy[2]
    far = cam.depth_max / float(cam.col_cos.min())
    rgb = np.zeros((cam.height, cam.width, 3), dtype=np.uint8)
    depth = np.zeros((cam.height, cam.width), dtype=np.uint16)
    look = sim.world.look
    lighting = look.lighting
    pieces: list[tuple[Any, np.ndarray]] = []
    for i, ob in enumerate(sim.world.obstacles):
        centre = look.round_centres[i]
        ball = (look.sphere_z[i], look.sphere_r[i]) if not np.isnan(look.sphere_r[i]) else None
        pieces.append((SimpleNamespace(ob=ob, centre=centre, ball=ball), ob.segments()))
    for i, m in enumerate(sim.world.moving):  # moving obstacles (people) where they are now
        mover = SimpleNamespace(base=0.0, height=m.height, color=m.color)
        pieces.append(
            (
                SimpleNamespace(ob=mover, centre=np.array([np.nan, np.nan]), ball=None),
                sim._mover_outline(i, *m.position(sim.world_time)),
            )
        )
    floor_rgb = lit(lighting.floor if lighting.floor is not None else FLOOR_RGB, (0.0, 0.0, 1.0), lighting)
    sky_rgb = np.array(lighting.sky if lighting.sky is not None else SKY_RGB).astype(np.uint8)
    for u in range(cam.width):
        angle = yaw + cam.col_angles[u]
        spans = []  # (entry depth, exit depth, piece, the side entered by)
        for piece, segs in pieces:
            dists, which = ray_hits(x, y, angle, segs)
            near = dists <= far
            depths, which = dists[near] * cam.col_cos[u], which[near]
            if len(segs) == 1:  # a thin wall: no inside
                spans += [(d, d, piece, segs[0]) for d in depths]
            else:  # a closed outline: entering and leaving in turn
                spans += [
                    (depths[i], depths[i + 1], piece, segs[which[i]]) for i in range(0, len(depths) - 1, 2)
                ]
        for v in range(cam.height):
            slope = cam.row_slope[v]
            best: tuple[float, str, Any, Any] | None = None  # (hit depth, what is met, piece, side)
            for d_in, d_out, piece, side in spans:
                ob = piece.ob
                z_in = cam.cam_z + slope * d_in
                hit = None
                if ob.base - 1e-12 <= z_in <= ob.height + 1e-12 and d_in <= cam.depth_max:
                    hit = (d_in, "side")
                elif z_in > ob.height and slope < 0 and d_out <= cam.depth_max:
                    d = (ob.height - cam.cam_z) / slope
                    hit = (d, "lid") if d <= d_out else None
                elif z_in < ob.base and slope > 0 and d_out <= cam.depth_max:
                    d = (ob.base - cam.cam_z) / slope
                    hit = (d, "under") if d <= d_out else None
                if hit is not None and (best is None or hit[0] < best[0]):
                    best = (hit[0], hit[1], piece, side)
            if best is not None:
                d, what, piece, side = best
                if what == "lid":
                    normal = (0.0, 0.0, 1.0)
                elif what == "under":
                    normal = (0.0, 0.0, -1.0)
                else:
                    reach = d / cam.col_cos[u]
                    hx, hy = x + reach * math.cos(angle), y + reach * math.sin(angle)
                    if np.isnan(piece.centre[0]):  # a flat side: its normal on the camera's side
                        nx, ny = side[3] - side[1], side[0] - side[2]
                        if nx * (x - side[0]) + ny * (y - side[1]) < 0:
                            nx, ny = -nx, -ny
                    else:  # a round one: from its axis
                        nx, ny = hx - piece.centre[0], hy - piece.centre[1]
                    norm = math.hypot(nx, ny)
                    nx, ny = nx / norm, ny / norm
                    t = 0.0
                    if piece.ball is not None:  # a sphere: the normal tilts with the height met
                        t = min(max((cam.cam_z + slope * d - piece.ball[0]) / piece.ball[1], -1.0), 1.0)
                    across = math.sqrt(1.0 - t * t)
                    normal = (nx * across, ny * across, t)
                rgb[v, u] = lit(piece.ob.color, normal, lighting)
                depth[v, u] = round(d * 1000.0)
            elif slope < -1e-9:
                floor = cam.cam_z / -slope
                floor = floor if floor <= cam.depth_max else 0.0  # beyond the depth range: no data
                rgb[v, u] = floor_rgb
                depth[v, u] = round(floor * 1000.0)
            else:
                rgb[v, u] = sky_rgb
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
