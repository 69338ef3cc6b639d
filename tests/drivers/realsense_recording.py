"""A RealSense recording made of synthetic frames, written by librealsense's own recorder over a software
device: depth (z16) and colour (rgb8) streams of a known scene, with intrinsics and depth -> colour
extrinsics registered, so the driver under test reads it exactly as it reads a real camera's file.

The scene: a wall at ``WALL_MM`` millimetres, a nearer box in the left half of the image at
``BOX_MM``, coloured red where the box is and blue elsewhere; frame ``i`` adds ``i`` mm to the wall.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

W, H, FPS = 64, 48, 30
FX = FY = 50.0
WALL_MM, BOX_MM = 2000, 1000
BASELINE_M = 0.015  # the colour camera 15 mm to the side of the depth camera (x, optical axes)


def scene(i: int) -> tuple[np.ndarray, np.ndarray]:
    depth = np.full((H, W), WALL_MM + i, np.uint16)
    depth[:, : W // 2] = BOX_MM
    color = np.zeros((H, W, 3), np.uint8)
    color[..., 2] = 200
    color[:, : W // 2] = (220, 10, 10)
    return depth, color


def write_recording(path: Path, frames: int = 90) -> Path:
    """Record ``frames`` frame pairs at 30 fps; returns the file (``.db3``, librealsense >= 2.57)."""
    import pyrealsense2 as rs

    dev = rs.software_device()
    depth_sensor = dev.add_sensor("Stereo Module")
    color_sensor = dev.add_sensor("RGB Camera")
    intr = rs.intrinsics()
    intr.width, intr.height, intr.ppx, intr.ppy, intr.fx, intr.fy = W, H, W / 2, H / 2, FX, FY
    intr.model, intr.coeffs = rs.distortion.brown_conrady, [0.0] * 5

    def stream(kind: object, uid: int, bpp: int, fmt: object) -> object:
        s = rs.video_stream()
        s.type, s.index, s.uid, s.width, s.height, s.fps, s.bpp, s.fmt, s.intrinsics = (
            kind,
            0,
            uid,
            W,
            H,
            FPS,
            bpp,
            fmt,
            intr,
        )
        return s

    dprof = depth_sensor.add_video_stream(stream(rs.stream.depth, 0, 2, rs.format.z16))
    cprof = color_sensor.add_video_stream(stream(rs.stream.color, 1, 3, rs.format.rgb8))
    depth_sensor.add_read_only_option(rs.option.depth_units, 0.001)
    ex = rs.extrinsics()
    ex.rotation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    ex.translation = [BASELINE_M, 0.0, 0.0]
    dprof.register_extrinsics_to(cprof, ex)
    dev.register_info(rs.camera_info.name, "Intel RealSense D435 (synthetic)")
    dev.register_info(rs.camera_info.serial_number, "000000000001")
    target = path.with_suffix(".db3")
    recorder = rs.recorder(str(target), dev)
    queue = rs.frame_queue(2 * frames)
    depth_sensor.open(dprof)
    color_sensor.open(cprof)
    depth_sensor.start(queue)
    color_sensor.start(queue)
    start_ms = time.time() * 1000.0
    for i in range(frames):
        depth, color = scene(i)
        for sensor, prof, pixels, bpp in ((depth_sensor, dprof, depth, 2), (color_sensor, cprof, color, 3)):
            f = rs.software_video_frame()
            f.pixels, f.stride, f.bpp = pixels, W * bpp, bpp
            f.timestamp, f.domain, f.frame_number = (
                start_ms + i * 1000.0 / FPS,
                rs.timestamp_domain.system_time,
                i,
            )
            f.profile = prof.as_video_stream_profile()
            sensor.on_video_frame(f)
        time.sleep(1.0 / FPS)
    for sensor in (depth_sensor, color_sensor):
        sensor.stop()
        sensor.close()
    del recorder
    return target
