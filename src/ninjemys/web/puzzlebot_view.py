"""The PuzzleBot simulator's browser view, a page of the web tools app (as turtlesim's window is).

``/puzzlebot`` draws the world from above (walls, furniture, floor markings), the robots with their
trails and lidar rays, and the selected robot's colour and depth images; the keyboard (arrows or
WASD, space to stop) drives the selected robot. The page gets the static world once
(``/api/puzzlebot/state``), then updates over Server-Sent Events at most 20 times a wall-clock second
(``/api/puzzlebot/events``); camera images are PNGs fetched on demand
(``/api/puzzlebot/camera.png?robot=NAME&kind=color|depth``), and rendered only while a page asks
for them. Keyboard commands arrive as ``POST /api/puzzlebot/cmd_vel`` and go to the robot exactly as
a ``cmd_vel`` message would; ``POST /api/puzzlebot/control`` pauses, resumes and resets.
"""

from __future__ import annotations

import argparse
import math
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from ninjemys.commands import entry
from ninjemys.serve.events import Hub
from ninjemys.serve.http import EventStream, Request, Response
from ninjemys.sim.render import png_bytes
from ninjemys.web.app import WebApp
from ninjemys.web.browser import open_if_display

if TYPE_CHECKING:
    from ninjemys.node.log import NodeLog
    from ninjemys.sim.puzzlebot_node import SimNode

UPDATE_PERIOD = 0.05  # wall seconds between updates sent to the pages
CAMERA_INTEREST = 2.0  # a camera stays rendered this long after the page last fetched an image


class PuzzlebotView:
    """Adds ``/puzzlebot`` and its API to a :class:`WebApp`; :meth:`publish` runs on the sim thread."""

    def __init__(self, app: WebApp, sim_node: SimNode) -> None:
        self.app = app
        self.sim_node = sim_node
        self.hub: Hub | None = None
        self._last_sent = 0.0
        self._trail_sent: dict[str, int] = {}
        self._frames: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._camera_wanted: dict[str, float] = {}
        self._frames_lock = threading.Lock()
        app.add_page("PuzzleBot", "/puzzlebot")
        s = app.server
        s.route("GET", "/puzzlebot", lambda _r: app._static_page("puzzlebot.html"))
        s.route("GET", "/api/puzzlebot/state", self._state_response)
        s.route("GET", "/api/puzzlebot/events", self._events)
        s.route("GET", "/api/puzzlebot/camera.png", self._camera_png)
        s.route("POST", "/api/puzzlebot/cmd_vel", self._cmd_vel)
        s.route("POST", "/api/puzzlebot/control", self._control)

    def attach(self) -> None:
        """Create the event hub (the app must be started)."""
        self.hub = self.app.hub()

    # -- what the sim thread asks -----------------------------------------------------------------
    def wants_scans(self) -> bool:
        return self.hub is not None and self.hub.listeners > 0

    def wants_camera(self, robot: str) -> bool:
        return time.monotonic() - self._camera_wanted.get(robot, -1e9) < CAMERA_INTEREST

    def camera_frame(self, robot: str, rgb: np.ndarray, depth: np.ndarray) -> None:
        with self._frames_lock:
            self._frames[robot] = (rgb, depth)

    # -- state ----------------------------------------------------------------------------------
    def _full_state(self) -> dict:
        """The static world and the robots (call with the sim lock held)."""
        sim = self.sim_node.sim
        w = sim.world
        obstacles = [
            {
                "name": o.name,
                "kind": o.kind,
                "outline": np.round(o.outline, 4).tolist(),
                "color": list(o.color),
                "height": o.height,
            }
            for o in w.obstacles
        ]
        grid_edges = np.round(sim.map_edges(), 4).tolist()
        markings = [
            {
                "points": np.round(m.points, 4).tolist(),
                "closed": m.closed,
                "width": m.width,
                "color": list(m.color),
            }
            for m in w.markings
        ]
        self._trail_sent = {}
        return {
            "node": self.sim_node.node.name,
            "world": w.name,
            "bounds": list(w.extent()),
            "obstacles": obstacles,
            "grid_edges": grid_edges,
            "markings": markings,
            "update": self._update(full_trails=True),
        }

    def _update(self, full_trails: bool = False) -> dict:
        sim = self.sim_node.sim
        robots = []
        for name, io in self.sim_node.io.items():
            r = io.robot
            total = r.trail_count
            sent = 0 if full_trails else self._trail_sent.get(name, 0)
            restart = full_trails or sent > total  # a reset cleared the trail
            if restart:
                sent = 0
            fresh = min(total - sent, len(r.trail))
            self._trail_sent[name] = total
            scan = None
            if io.last_scan is not None and r.model.laser is not None:
                ranges = io.last_scan
                scan = {
                    "ranges": [round(float(v), 3) if math.isfinite(v) else None for v in ranges],
                    "angle_min": -math.pi,
                    "increment": 2.0 * math.pi / len(ranges),
                    "offset": list(r.model.laser.pose.xyz[:2]),
                }
            robots.append(
                {
                    "name": name,
                    "namespace": "/" + io.prefix.rstrip("/") if io.prefix else "",
                    "x": round(r.x, 4),
                    "y": round(r.y, 4),
                    "yaw": round(r.yaw, 4),
                    "v": round(r.v, 3),
                    "w": round(r.w, 3),
                    "radius": r.model.body_radius,
                    "color": list(r.model.color),
                    "contact": r.contact,
                    "contact_with": r.contact_with,
                    "camera": r.model.camera is not None,
                    "trail": list(r.trail)[len(r.trail) - fresh :] if fresh > 0 else [],
                    "trail_reset": restart,
                    "scan": scan,
                }
            )
        movers = [
            {
                "name": m.name,
                "outline": np.round(m.outline_at(sim.world_time), 3).tolist(),
                "color": list(m.color),
            }
            for m in sim.world.moving
        ]
        return {
            "time": round(sim.time, 3),
            "paused": self.sim_node.paused,
            "robots": robots,
            "movers": movers,
        }

    def _state_response(self, _request: Request) -> Response:
        with self.sim_node.lock:
            return Response(self._full_state())

    def _events(self, _request: Request) -> EventStream:
        assert self.hub is not None
        with self.sim_node.lock:
            return self.hub.open([("state", self._full_state())])

    def _resync(self) -> dict:
        with self.sim_node.lock:
            return self._full_state()

    def publish(self, _sim_time: float) -> None:
        """Send robots, trails, scans and movers to the open pages (sim lock held; throttled)."""
        if self.hub is None or self.hub.listeners == 0:
            return
        now = time.monotonic()
        if now - self._last_sent < UPDATE_PERIOD:
            return
        self._last_sent = now
        self.hub.publish("update", self._update(), resync=self._resync)

    # -- camera and commands ----------------------------------------------------------------------
    def _camera_png(self, request: Request) -> Response:
        robot = request.arg("robot", "") or ""
        kind = request.arg("kind", "color")
        self._camera_wanted[robot] = time.monotonic()
        with self._frames_lock:
            frame = self._frames.get(robot)
        if frame is None:
            return Response({"error": f"no camera image of robot [{robot}] yet"}, 404)
        rgb, depth = frame
        if kind == "depth":
            d = depth.astype(np.float32)
            scaled = np.where(d > 0, 255.0 - np.clip(d / 40.0, 0, 235), 0).astype(
                np.uint8
            )  # near bright, 10 m dark
            image = np.repeat(scaled[:, :, None], 3, axis=2)
        else:
            image = rgb
        return Response(png_bytes(image), 200, "image/png", {"Cache-Control": "no-store"})

    def _cmd_vel(self, request: Request) -> Response:
        try:
            body = request.json()
            robot = str(body["robot"])
            linear = float(body["linear"])
            angular = float(body["angular"])
        except (ValueError, KeyError, TypeError):
            return Response({"error": "expected {robot, linear, angular}"}, 400)
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return Response({"error": "linear and angular must be finite"}, 400)
        with self.sim_node.lock:
            io = self.sim_node.io.get(robot)
            if io is None:
                return Response({"error": f"no robot [{robot}]"}, 404)
            io.robot.command(linear, angular)
        return Response({"ok": True})

    def _control(self, request: Request) -> Response:
        try:
            action = str(request.json()["action"])
        except (ValueError, KeyError, TypeError):
            return Response({"error": "expected {action}"}, 400)
        handlers = {
            "pause": self.sim_node._pause,
            "unpause": self.sim_node._unpause,
            "reset_world": self.sim_node._reset_world,
            "reset_simulation": self.sim_node._reset_simulation,
        }
        if action not in handlers:
            return Response({"error": f"unknown action {action!r}"}, 400)
        handlers[action](None)
        return Response({"ok": True})


def start_view(sim_node: SimNode, options: argparse.Namespace, log: NodeLog) -> Callable[[], None] | None:
    """Serve the PuzzleBot page and the node graph for a running simulator; returns the stop
    function (None when the server cannot start: the error is logged)."""
    node = sim_node.node
    web = WebApp(node.master_uri, node.name, options.host, options.port)
    view = PuzzlebotView(web, sim_node)
    try:
        url = web.start()
    except OSError as exc:
        log.error("cannot serve the simulator view on %s:%d: %s", options.host, options.port, exc)
        return None
    view.attach()
    sim_node.view = view
    print(f"puzzlebot_sim view: {url}puzzlebot   node graph: {url}", flush=True)
    if not options.no_browser:
        open_if_display(url + "puzzlebot")
    return web.stop


def main(argv: list[str] | None = None) -> int:
    """``rosrun puzzlebot_sim sim_node``: the simulator (:mod:`ninjemys.sim.puzzlebot_node`) with its view."""
    from ninjemys.sim import puzzlebot_node

    return puzzlebot_node.main(argv, view=start_view)


console_main = entry(main)


if __name__ == "__main__":
    console_main()
