"""The PuzzleBot simulator's browser view, a page of the web tools app (as turtlesim's window is),
and the ``sim_node`` command that shows it.

``/puzzlebot`` draws the world from above (the floor's pictures, a course's track; walls and
furniture in their colours, the taller over the lower, their shadows as long as they are tall, what
is held in the air see-through; floor markings), the robots with their trails and lidar rays, and the selected robot's colour and depth images; the keyboard (arrows or
WASD, space to stop) drives the selected robot. Everything goes through the gateway mounted on the
page's server, the browser's one data path: the page subscribes to the ``view:puzzlebot`` JSON
channel (the static world once, then updates at most 20 times a wall-clock second) and to the
robots' camera topics (rendered only while someone subscribes, as for any ROS client); it publishes
``cmd_vel`` like any teleop node and calls ``/gazebo/pause_physics``, ``unpause_physics``,
``reset_world`` and ``reset_simulation`` to pause, resume and reset.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.serve.http import Request, Response
from ninjemys.sim.simcore import scan_angles
from ninjemys.web.app import WebApp
from ninjemys.web.browser import open_if_display

if TYPE_CHECKING:
    from ninjemys.node.log import NodeLog
    from ninjemys.sim.puzzlebot_node import SimNode

UPDATE_PERIOD = 0.05  # wall seconds between updates sent to the pages
#: the gateway channel the page subscribes to (JSON; not a ROS topic, see ninjemys.bridge.appchannels)
CHANNEL = "view:puzzlebot"
#: the floor pictures of the world (``?i=<index>``), drawn under the models
FLOOR_ROUTE = "/api/puzzlebot/floor.png"
FLOOR_MAX_PIXELS = 2048


class PuzzlebotView:
    """The ``/puzzlebot`` page of a :class:`WebApp`, fed through the gateway mounted on it.

    The page subscribes to the gateway's :data:`CHANNEL` (the static world once, then robots,
    trails, scans and movers) and to the robots' camera topics; it drives by publishing ``cmd_vel``
    and pauses or resets through the ``/gazebo/*`` services, all through the gateway. The simulator
    calls :meth:`wants_scans` and :meth:`publish` (on its thread, with its lock held).
    """

    url = ""  # the page's address once served

    def __init__(self, app: WebApp, gateway: Gateway, sim_node: SimNode) -> None:
        self.sim_node = sim_node
        self._last_sent = 0.0
        self._trail_sent: dict[str, int] = {}
        app.add_page("PuzzleBot", "/puzzlebot")
        app.server.route("GET", "/puzzlebot", lambda _r: app._static_page("puzzlebot.html"))
        app.server.route("GET", "/api/puzzlebot/floor.png", self._floor_png)
        self._revision = -1
        self._pngs: dict[tuple[int, int], bytes] = {}
        self.channel = gateway.app_channel(CHANNEL, "ninjemys/PuzzlebotView", self._full_state, sim_node.lock)

    # -- what the sim thread asks -----------------------------------------------------------------
    def wants_scans(self) -> bool:
        return self.channel.listeners > 0

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
                "base": o.base,
                "model": o.model_name,
            }
            for o in w.obstacles
        ]
        self._revision = w.revision
        floor = [
            {
                "name": f.name,
                "url": f"{FLOOR_ROUTE}?i={i}&rev={w.revision}",
                "cx": f.cx,
                "cy": f.cy,
                "width": f.width,
                "height": f.height,
                "yaw": f.yaw,
            }
            for i, f in enumerate(w.floor_images)
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
            "kind": "state",
            "node": self.sim_node.node.name,
            "world": w.name,
            "bounds": list(w.extent()),
            "revision": w.revision,
            "obstacles": obstacles,
            "floor_images": floor,
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
                angle_min, _angle_max, increment = scan_angles(r.model.laser)
                scan = {
                    "ranges": [round(float(v), 3) if math.isfinite(v) else None for v in ranges],
                    "angle_min": angle_min,
                    "increment": increment,
                    "offset": list(r.model.laser.pose.xyz[:2]),
                }
            robots.append(
                {
                    "name": name,
                    "namespace": "/" + io.prefix.rstrip("/") if io.prefix else "",
                    # resolved names the page publishes to and subscribes to through the gateway
                    "topics": self._topics(io.topics),
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
            "kind": "update",
            "time": round(sim.time, 3),
            "paused": self.sim_node.paused,
            "robots": robots,
            "movers": movers,
        }

    def _floor_png(self, request: Request) -> Response:
        """A picture on the world's floor (a textured plane: a course's track) as PNG, at most
        :data:`FLOOR_MAX_PIXELS` a side (the page draws it under the models, to scale)."""
        try:
            index = int(request.arg("i", "") or "")
            image = self.sim_node.sim.world.floor_images[index]
        except (ValueError, IndexError):
            return Response(b"no such floor picture", 404, "text/plain; charset=utf-8")
        key = (index, id(image))
        png = self._pngs.get(key)
        if png is None:
            import cv2  # a dependency already (cv_bridge); only when a world has floor pictures

            bgr = np.ascontiguousarray(image.rgb[:, :, ::-1])
            side = max(bgr.shape[:2])
            if side > FLOOR_MAX_PIXELS:
                f = FLOOR_MAX_PIXELS / side
                bgr = cv2.resize(bgr, (max(1, round(bgr.shape[1] * f)), max(1, round(bgr.shape[0] * f))))
            ok, data = cv2.imencode(".png", bgr)
            if not ok:
                return Response(b"cannot encode the floor picture", 500, "text/plain; charset=utf-8")
            png = self._pngs[key] = data.tobytes()
        return Response(png, 200, "image/png")

    def _topics(self, topics: dict[str, str]) -> dict[str, str]:
        """The robot's command and camera topics, resolved (its model names them)."""
        resolve = self.sim_node.node.resolve_name
        return {role: resolve(name) for role, name in topics.items()}

    def publish(self, _sim_time: float) -> None:
        """Send robots, trails, scans and movers to the open pages (sim lock held; throttled)."""
        if self.channel.listeners == 0:
            return
        now = time.monotonic()
        if now - self._last_sent < UPDATE_PERIOD:
            return
        self._last_sent = now
        if self.sim_node.sim.world.revision != self._revision:
            # a model was spawned, moved or deleted: the pages get the world again
            self.channel.publish(self._full_state())
            return
        self.channel.publish(self._update())


def start_view(sim_node: SimNode, options: argparse.Namespace, log: NodeLog) -> Callable[[], None] | None:
    """Serve the PuzzleBot page and the node graph for a running simulator, with the gateway (on the
    simulator's own node: no extra node in the graph) as the pages' data path; returns the stop
    function (None when the server cannot start: the error is logged)."""
    node = sim_node.node
    gateway = Gateway(GatewayOptions(node_name=node.name, sim_clock=False), node=node)
    gateway.start()
    web = WebApp(node.master_uri, node.name, options.host, options.port)
    web.add_gateway(gateway)
    view = PuzzlebotView(web, gateway, sim_node)
    try:
        url = web.start()
    except OSError as exc:
        gateway.shutdown()
        log.error("cannot serve the simulator view on %s:%d: %s", options.host, options.port, exc)
        return None
    view.url = url + "puzzlebot"
    sim_node.view = view
    print(f"puzzlebot_sim view: {url}puzzlebot   node graph: {url}", flush=True)
    if not options.no_browser:
        open_if_display(url + "puzzlebot")

    def stop() -> None:
        sim_node.view = None
        web.stop()
        gateway.shutdown()

    return stop


def main(argv: list[str] | None = None) -> int:
    """``rosrun puzzlebot_sim sim_node``: the simulator (:mod:`ninjemys.sim.puzzlebot_node`) with its view."""
    from ninjemys.sim import puzzlebot_node

    return puzzlebot_node.main(argv, view=start_view)


console_main = entry(main)


if __name__ == "__main__":
    console_main()
