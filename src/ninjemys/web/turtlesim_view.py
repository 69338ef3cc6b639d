"""The turtlesim window as a page of the web tools app, and the ``turtlesim_node`` command that shows it.

The browser keeps its own copy of the path image: it starts from a PNG of the current path (sent
when the page connects) and then draws the pen segments each update carries, so the stream stays
small however long the turtles have been drawing. Turtles are redrawn from their poses.
"""

from __future__ import annotations

import argparse
import base64
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.commands import entry
from ninjemys.serve.http import Request, Response
from ninjemys.sim.render import compose_frame, png_bytes
from ninjemys.sim.world import CANVAS_PIXELS, PIXELS_PER_METER, Segment, Turtle, World
from ninjemys.web.app import WebApp
from ninjemys.web.browser import open_if_display

if TYPE_CHECKING:
    from ninjemys.sim.turtlesim_node import TurtlesimNode


def turtle_json(turtle: Turtle) -> dict:
    return {
        "name": turtle.name,
        "x": turtle.x,
        "y": turtle.y,
        "theta": turtle.theta,
        "image": turtle.image_index,
        "pen": None if turtle.pen.off else [turtle.pen.r, turtle.pen.g, turtle.pen.b, turtle.pen.width],
    }


def segment_json(s: Segment) -> list:
    return [round(s.x0, 5), round(s.y0, 5), round(s.x1, 5), round(s.y1, 5), s.r, s.g, s.b, s.width]


#: the gateway channel the page subscribes to (JSON; not a ROS topic, see ninjemys.bridge.appchannels)
CHANNEL = "view:turtlesim"


class TurtlesimView:
    """The ``/turtlesim`` page of a :class:`WebApp`, fed through the gateway mounted on it.

    The page subscribes to the gateway's :data:`CHANNEL`: a new subscriber gets the full state (path
    PNG, turtles), then updates. ``world`` is shared with the node; every access holds ``lock``.
    Call :meth:`publish` after each world step with the lock held; it sends what changed since the
    previous call, and nothing while no page is open. ``/api/turtlesim/snapshot.png`` is the
    server's own rendering (for checks and for saving a picture).
    """

    def __init__(
        self, app: WebApp, gateway: Gateway, world: World, lock: threading.Lock, node_name: str
    ) -> None:
        self.world = world
        self.lock = lock
        self.node_name = node_name
        self._sent_segments = world.segment_total
        self._sent_clear = world.clear_count
        self._last_poses: list | None = None
        app.add_page("Turtlesim", "/turtlesim")
        s = app.server
        s.route("GET", "/turtlesim", lambda _r: app._static_page("turtlesim.html"))
        s.route("GET", "/api/turtlesim/snapshot.png", self._snapshot)
        self.channel = gateway.app_channel(CHANNEL, "ninjemys/TurtlesimView", self._full_state, lock)

    def _full_state(self) -> dict:
        """Everything a freshly subscribed page needs (call with the lock held)."""
        w = self.world
        return {
            "kind": "state",
            "node": self.node_name,
            "size": CANVAS_PIXELS,
            "scale": PIXELS_PER_METER,
            "world": w.width,
            "background": list(w.background),
            "path_png": base64.b64encode(png_bytes(w.image)).decode("ascii"),
            "turtles": [turtle_json(t) for t in w.turtles.values()],
        }

    def _snapshot(self, _request: Request) -> Response:
        with self.lock:
            frame = compose_frame(self.world)
        return Response(png_bytes(frame), 200, "image/png", {"Cache-Control": "no-store"})

    def publish(self) -> None:
        """Send the turtles and new pen segments to every open page (call with the lock held)."""
        w = self.world
        if self.channel.listeners == 0:
            self._sent_segments = w.segment_total
            self._sent_clear = w.clear_count
            self._last_poses = None
            return
        pending = w.segment_total - self._sent_segments
        if w.clear_count != self._sent_clear or pending > len(w.segments):
            self._sent_clear = w.clear_count
            self._sent_segments = w.segment_total
            self._last_poses = None
            self.channel.publish(self._full_state())
            return
        new = w.segments[len(w.segments) - pending :] if pending else []
        self._sent_segments = w.segment_total
        poses = [turtle_json(t) for t in w.turtles.values()]
        if not new and poses == self._last_poses:
            return
        self._last_poses = poses
        self.channel.publish({"kind": "update", "turtles": poses, "segments": [segment_json(s) for s in new]})


def start_view(
    sim: TurtlesimNode, options: argparse.Namespace, ros_args: list[str]
) -> Callable[[], None] | None:
    """Serve the turtlesim page and the node graph for a running sim, with the gateway (on the
    turtlesim node itself: no extra node in the graph) as the pages' data path; returns the stop
    function (None when the server cannot start: the error is logged)."""
    node = sim.node
    gateway = Gateway(GatewayOptions(node_name=node.name, sim_clock=False), node=node)
    gateway.start()
    app = WebApp(node.master_uri, node.name, options.host, options.port)
    app.add_gateway(gateway)
    view = TurtlesimView(app, gateway, sim.world, sim.lock, node.name)
    try:
        url = app.start()
    except OSError as exc:
        gateway.shutdown()
        node.log.error("cannot serve the turtlesim view on %s:%d: %s", options.host, options.port, exc)
        return None
    sim.view = view
    print(f"turtlesim view: {url}turtlesim   node graph: {url}", flush=True)
    if not options.no_browser:
        open_if_display(url + "turtlesim")  # where ROS would open its window

    def stop() -> None:
        sim.view = None
        app.stop()
        gateway.shutdown()

    return stop


def main(argv: list[str] | None = None) -> int:
    """``turtlesim_node``: the simulator (:mod:`ninjemys.sim.turtlesim_node`) with its browser view."""
    from ninjemys.sim import turtlesim_node

    return turtlesim_node.main(argv, view=start_view)


console_main = entry(main)


if __name__ == "__main__":
    console_main()
