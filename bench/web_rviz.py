"""rviz in headless chromium: frame time and page CPU with a navigation scene, a 100k-point cloud at
10 Hz, and publish-to-paint latency of a small marker.

    .venv/bin/python bench/web_rviz.py [--seconds 10] [--points 100000]

The scene is published by a ninjemys node in this process: a 400x400 map (latched), a 360-beam scan
at 10 Hz, TF (map->odom->base_link->laser) at 30 Hz, a 200-pose path at 1 Hz and 500 amcl particles at
10 Hz. The page is our rviz (``ninjemys.web.rviz.Rviz``: node + gateway + web app) in Debian's
chromium (software GL: no GPU here). ROS 1's rviz is a Qt/OGRE desktop program that needs an X display
and OpenGL, so it cannot run side by side on this machine; the figures are set against the budgets
the issue names instead (30 fps = 33.3 ms a frame, 10 Hz clouds, 50 ms publish-to-paint), and the
ratio printed is figure / budget.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import threading
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np  # noqa: E402

from ninjemys.idl.loader import get_message_class as M  # noqa: E402, N812
from ninjemys.master.core import MasterThread  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.rostime import Time  # noqa: E402
from ninjemys.web.rviz import Rviz  # noqa: E402

CHROMIUM = "/usr/bin/chromium"

SCENE = """
Visualization Manager:
  Displays:
    - {Class: rviz/Grid, Name: Grid, Enabled: true}
    - {Class: rviz/Map, Name: Map, Enabled: true, Topic: /map}
    - {Class: rviz/LaserScan, Name: Scan, Enabled: true, Topic: /scan}
    - {Class: rviz/TF, Name: TF, Enabled: true}
    - {Class: rviz/Path, Name: Path, Enabled: true, Topic: /path}
    - {Class: rviz/PoseArray, Name: Particles, Enabled: true, Topic: /particlecloud}
    - {Class: rviz/PointCloud2, Name: Cloud, Enabled: true, Topic: /cloud}
    - {Class: rviz/Marker, Name: Marker, Enabled: true, Marker Topic: /marker}
  Global Options: {Fixed Frame: map}
"""


def _tf(parent: str, child: str, x: float, y: float, yaw: float, stamp: Time) -> Any:
    ts = M("geometry_msgs/TransformStamped")()
    ts.header.frame_id, ts.header.stamp, ts.child_frame_id = parent, stamp, child
    ts.transform.translation.x, ts.transform.translation.y = x, y
    ts.transform.rotation.z, ts.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return ts


class Scene:
    """Publishers of the navigation scene (and, on demand, the cloud), each on its own thread."""

    def __init__(self, node: Node, points: int) -> None:
        self.node = node
        self.stop = threading.Event()
        self.threads: list[threading.Thread] = []
        grid = M("nav_msgs/OccupancyGrid")()
        grid.header.frame_id = "map"
        grid.info.resolution, grid.info.width, grid.info.height = 0.05, 400, 400
        grid.info.origin.position.x = grid.info.origin.position.y = -10.0
        grid.info.origin.orientation.w = 1.0
        cells = np.zeros((400, 400), dtype=np.int8)
        cells[::40, :] = 100
        cells[:, ::40] = 100
        grid.data = cells.tobytes()
        self.map_pub = node.publisher("/map", M("nav_msgs/OccupancyGrid"), queue_size=1, latch=True)
        self.map_pub.publish(grid)
        self.pubs = {
            "scan": node.publisher("/scan", M("sensor_msgs/LaserScan"), queue_size=1),
            "tf": node.publisher("/tf", M("tf2_msgs/TFMessage"), queue_size=10),
            "path": node.publisher("/path", M("nav_msgs/Path"), queue_size=1),
            "particles": node.publisher("/particlecloud", M("geometry_msgs/PoseArray"), queue_size=1),
            "cloud": node.publisher("/cloud", M("sensor_msgs/PointCloud2"), queue_size=1),
            "marker": node.publisher("/marker", M("visualization_msgs/Marker"), queue_size=1),
        }
        self.points = points

    def every(self, hz: float, fn: Any) -> None:
        def loop() -> None:
            period = 1.0 / hz
            next_t = time.monotonic()
            i = 0
            while not self.stop.is_set():
                fn(i)
                i += 1
                next_t += period
                self.stop.wait(max(0.0, next_t - time.monotonic()))

        t = threading.Thread(target=loop, daemon=True)
        t.start()
        self.threads.append(t)

    def start_navigation(self) -> None:
        scan = M("sensor_msgs/LaserScan")(
            angle_min=-math.pi, angle_increment=2 * math.pi / 360, range_max=10.0
        )
        scan.header.frame_id = "laser"
        scan.angle_max = math.pi - scan.angle_increment
        scan.range_min = 0.05
        scan.ranges = [2.0 + math.sin(i / 10) for i in range(360)]
        self.every(10, lambda i: self.pubs["scan"].publish(scan))

        def tf(i: int) -> None:
            stamp = Time.from_sec(time.time())
            yaw = i * 0.01
            self.pubs["tf"].publish(
                M("tf2_msgs/TFMessage")(
                    transforms=[
                        _tf("map", "odom", 0.1, 0.0, 0.0, stamp),
                        _tf("odom", "base_link", math.cos(yaw), math.sin(yaw), yaw, stamp),
                        _tf("base_link", "laser", 0.0, 0.0, 0.0, stamp),
                    ]
                )
            )

        self.every(30, tf)
        path = M("nav_msgs/Path")()
        path.header.frame_id = "map"
        for k in range(200):
            p = M("geometry_msgs/PoseStamped")()
            p.pose.position.x, p.pose.position.y = k * 0.05, math.sin(k / 20)
            p.pose.orientation.w = 1.0
            path.poses.append(p)
        self.every(1, lambda i: self.pubs["path"].publish(path))
        rng = np.random.default_rng(0)
        particles = M("geometry_msgs/PoseArray")()
        particles.header.frame_id = "map"
        for _ in range(500):
            p = M("geometry_msgs/Pose")()
            p.position.x, p.position.y = rng.normal(1.0, 0.3), rng.normal(0.0, 0.3)
            yaw = rng.uniform(-math.pi, math.pi)
            p.orientation.z, p.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            particles.poses.append(p)
        self.every(10, lambda i: self.pubs["particles"].publish(particles))

    def start_cloud(self) -> None:
        n = self.points
        cloud = M("sensor_msgs/PointCloud2")(height=1, width=n, point_step=16, row_step=16 * n, is_dense=True)
        cloud.header.frame_id = "map"
        cloud.fields = [
            M("sensor_msgs/PointField")(name=c, offset=4 * i, datatype=7, count=1)
            for i, c in enumerate("xyz")
        ] + [M("sensor_msgs/PointField")(name="rgb", offset=12, datatype=7, count=1)]
        rng = np.random.default_rng(1)
        data = np.zeros((n, 4), dtype="<f4")
        data[:, :3] = rng.uniform(-3, 3, (n, 3))
        cloud.data = data.tobytes()
        self.every(10, lambda i: self.pubs["cloud"].publish(cloud))

    def marker(self) -> None:
        mk = M("visualization_msgs/Marker")(ns="lat", id=0, type=1, action=0)
        mk.header.frame_id = "map"
        mk.header.stamp = Time.from_sec(time.time())
        mk.pose.orientation.w = 1.0
        mk.scale.x = mk.scale.y = mk.scale.z = 0.3
        mk.color.r = mk.color.a = 1.0
        self.pubs["marker"].publish(mk)

    def close(self) -> None:
        self.stop.set()
        for t in self.threads:
            t.join(2.0)


def _cpu(cdp: Any) -> float:
    metrics = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
    return float(metrics["TaskDuration"])


def _measure(page: Any, cdp: Any, seconds: float) -> dict[str, float]:
    page.evaluate("rviz.stats.frameMs.length = 0; rviz.stats.frames = 0")
    received0 = page.evaluate("rviz.displays.map(d => d.received)")
    cpu0, t0 = _cpu(cdp), time.monotonic()
    time.sleep(seconds)
    cpu1, t1 = _cpu(cdp), time.monotonic()
    frame_ms = page.evaluate("rviz.stats.frameMs.slice()")
    received1 = page.evaluate("rviz.displays.map(d => d.received)")
    names = page.evaluate("rviz.displays.map(d => d.cfg.name)")
    rates = {n: (b - a) / (t1 - t0) for n, a, b in zip(names, received0, received1, strict=True)}
    return {
        "fps": len(frame_ms) / (t1 - t0),
        "p50": statistics.median(frame_ms) if frame_ms else float("nan"),
        "p95": float(np.percentile(frame_ms, 95)) if frame_ms else float("nan"),
        "cpu": 100.0 * (cpu1 - cpu0) / (t1 - t0),
        **{f"rate:{k}": v for k, v in rates.items()},
    }


# publish-to-paint: the marker's header stamp (its publish time) to the end of the first render after
# the page decoded it (both clocks are this machine's wall clock)
LATENCY_HOOK = """() => {
  window.lat = []; window.parts = []; window.pending = null;
  const d = rviz.displays.find(d => d.cfg.name === 'Marker');
  const orig = d.onMessage.bind(d);
  d.onMessage = (m, info) => { orig(m, info);
    const sent = m.header.stamp.secs * 1000 + m.header.stamp.nsecs / 1e6;
    window.pending = { sent, gateway: info.receiveTimeNs / 1e6, page: Date.now() }; };
  rviz.frameHooks.push(() => { const p = window.pending; if (p !== null) { const now = Date.now();
    lat.push(now - p.sent); parts.push([p.gateway - p.sent, p.page - p.gateway, now - p.page]);
    window.pending = null; } });
}"""


def _latency(page: Any, scene: Scene, samples: int) -> list[float]:
    page.evaluate("lat.length = 0; parts.length = 0")
    for _ in range(samples):
        scene.marker()
        time.sleep(0.15)
    page.wait_for_timeout(500)
    parts = np.array(page.evaluate("parts")).reshape(-1, 3)
    if len(parts):
        med = np.median(parts, axis=0)
        print(
            f"  latency parts (median ms): publish->gateway {med[0]:.1f}, gateway->page {med[1]:.1f},"
            f" page->painted {med[2]:.1f}"
        )
    return list(page.evaluate("lat"))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--markers", type=int, default=40, help="latency samples")
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    tmp = Path(os.environ.get("TMPDIR", "/tmp")) / f"bench_rviz_{os.getpid()}.rviz"
    tmp.write_text(SCENE)
    print(f"load average: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (2 cores shared)")
    with MasterThread() as uri:
        node = Node("bench_scene", anonymous=True, master_uri=uri)
        rviz = Rviz(uri, str(tmp), update_period=0.2)
        scene = Scene(node, args.points)
        try:
            url = rviz.start()
            with sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"])
                page = browser.new_page(viewport={"width": 1280, "height": 800})
                cdp = page.context.new_cdp_session(page)
                cdp.send("Performance.enable")
                page.goto(url + "?view=top&scale=40")
                page.wait_for_function(
                    "window.rviz && window.rviz.ready && rviz.ros.connected", timeout=30000
                )
                page.wait_for_timeout(1500)
                idle = _measure(page, cdp, 3.0)
                page.evaluate(LATENCY_HOOK)
                lat_idle = _latency(page, scene, args.markers)
                scene.start_navigation()
                page.wait_for_timeout(2000)
                nav = _measure(page, cdp, args.seconds)
                lat_nav = _latency(page, scene, args.markers)
                scene.start_cloud()
                page.wait_for_timeout(2000)
                cloud = _measure(page, cdp, args.seconds)
                browser.close()
        finally:
            scene.close()
            rviz.stop()
            node.shutdown("bench over")
            tmp.unlink(missing_ok=True)

    def row(name: str, value: float, unit: str, budget: float | None) -> None:
        ratio = f"{value / budget:6.2f}" if budget else "     -"
        print(f"{name:<58} {value:9.1f} {unit:<6} budget {budget if budget else '-':>6} ratio {ratio}")

    print(f"{'':<58} {'ours':>9}")
    row("idle page: frames/s", idle["fps"], "fps", None)
    row("idle page: page CPU (main thread)", idle["cpu"], "%", None)
    row("map+scan+TF+path+particles: frame time p50", nav["p50"], "ms", 33.3)
    row("map+scan+TF+path+particles: frame time p95", nav["p95"], "ms", 33.3)
    row("map+scan+TF+path+particles: frames/s", nav["fps"], "fps", 30.0)
    row("map+scan+TF+path+particles: page CPU (main thread)", nav["cpu"], "%", None)
    row("  scan messages drawn/s (published 10/s)", nav["rate:Scan"], "Hz", 10.0)
    row("  particle clouds drawn/s (published 10/s)", nav["rate:Particles"], "Hz", 10.0)
    row(
        f"+ {args.points} point PointCloud2: clouds drawn/s (published 10/s)", cloud["rate:Cloud"], "Hz", 10.0
    )
    row(f"+ {args.points} point PointCloud2: frames/s", cloud["fps"], "fps", 30.0)
    row(f"+ {args.points} point PointCloud2: frame time p95", cloud["p95"], "ms", 33.3)
    row(f"+ {args.points} point PointCloud2: page CPU", cloud["cpu"], "%", None)
    for what, lat in (("idle page", lat_idle), ("with the navigation scene", lat_nav)):
        if lat:
            row(f"marker publish-to-paint p50, {what} ({len(lat)})", statistics.median(lat), "ms", 50.0)
            row(f"marker publish-to-paint p95, {what}", float(np.percentile(lat, 95)), "ms", 50.0)
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
