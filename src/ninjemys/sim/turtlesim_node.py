"""``turtlesim_node``: ROS turtlesim's interface over the pure :mod:`ninjemys.sim.world`.

Topics per turtle ``<name>/cmd_vel`` (in), ``<name>/pose`` and ``<name>/color_sensor`` (out); services
``clear``, ``reset``, ``spawn``, ``kill`` and per turtle ``set_pen``, ``teleport_absolute``,
``teleport_relative``; parameters ``~background_r/g/b``. Instead of a Qt window the view is a page of
the web tools app (:mod:`ninjemys.web.turtlesim_view`, which the ``turtlesim_node`` command wires in)
whose URL the node prints; ``--headless`` skips the web server and changes nothing else.

The world is stepped every 16 ms on one thread; service handlers and velocity callbacks run on the
runtime's threads and take the same lock, so every change is atomic with respect to a step.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from geometry_msgs.msg import Twist
from ninjemys.commands import entry
from ninjemys.errors import NinjemysError, ServiceError, ShutdownError
from ninjemys.node.node import Node
from ninjemys.node.run import run_node
from ninjemys.sim.world import CENTER, DEFAULT_BACKGROUND, UPDATE_PERIOD, TurtleError, World
from std_srvs.srv import Empty, EmptyResponse
from turtlesim.msg import Color, Pose
from turtlesim.srv import (
    Kill,
    KillResponse,
    SetPen,
    SetPenResponse,
    Spawn,
    SpawnResponse,
    TeleportAbsolute,
    TeleportAbsoluteResponse,
    TeleportRelative,
    TeleportRelativeResponse,
)


@dataclass
class _TurtleIO:
    """The ROS endpoints of one turtle; closed together when the turtle is killed."""

    pose: Any
    color: Any
    cmd_vel: Any
    services: list[Any]

    def close(self) -> None:
        self.cmd_vel.unregister()
        self.pose.unregister()
        self.color.unregister()
        for srv in self.services:
            srv.shutdown()


class TurtlesimNode:
    """Binds one :class:`World` to the ROS topics and services of ``node`` (a core Node)."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.lock = threading.Lock()
        self.world = World(self._background(), warn=node.log.warn, info=node.log.info)
        self.io: dict[str, _TurtleIO] = {}
        self.view: Any = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        node.service("clear", Empty, self._clear)
        node.service("reset", Empty, self._reset)
        node.service("spawn", Spawn, self._spawn)
        node.service("kill", Kill, self._kill)
        node.log.info("Starting turtlesim with node name %s", node.name)
        with self.lock:
            self._add(self.world.spawn("", CENTER, CENTER, 0.0).name)

    # -- parameters ------------------------------------------------------------------------------
    def _background(self) -> tuple[int, int, int]:
        values = []
        for key, default in zip(("r", "g", "b"), DEFAULT_BACKGROUND, strict=True):
            try:
                value = self.node.get_param("~background_" + key, default)
            except NinjemysError as exc:  # master away: keep simulating with the default colour
                self.node.log.warn("~background_%s: %s; using %d", key, exc, default)
                value = default
            try:
                values.append(int(value) & 0xFF)
            except (TypeError, ValueError):
                self.node.log.warn("~background_%s: %r is not an integer, using %d", key, value, default)
                values.append(default)
        return values[0], values[1], values[2]

    # -- turtles ---------------------------------------------------------------------------------
    def _add(self, name: str) -> None:
        """Create the topics and services of a turtle that exists in the world (lock held)."""
        node = self.node
        pose = node.publisher(f"{name}/pose", Pose, queue_size=1)
        color = node.publisher(f"{name}/color_sensor", Color, queue_size=1)
        cmd = node.subscriber(f"{name}/cmd_vel", Twist, self._on_cmd_vel, callback_args=name, queue_size=1)
        services = [
            node.service(f"{name}/set_pen", SetPen, partial(self._set_pen, name)),
            node.service(f"{name}/teleport_absolute", TeleportAbsolute, partial(self._teleport_abs, name)),
            node.service(f"{name}/teleport_relative", TeleportRelative, partial(self._teleport_rel, name)),
        ]
        self.io[name] = _TurtleIO(pose, color, cmd, services)

    def _remove(self, name: str) -> None:
        io = self.io.pop(name, None)
        if io is not None:
            io.close()

    def _on_cmd_vel(self, msg: Twist, name: str) -> None:
        with self.lock:
            if name in self.world.turtles:
                self.world.command(name, msg.linear.x, msg.linear.y, msg.angular.z, time.monotonic())

    # -- services --------------------------------------------------------------------------------
    def _refuse(self, exc: TurtleError) -> None:
        self.node.log.error("%s", exc)
        raise ServiceError(str(exc)) from None

    def _clear(self, _req: Any) -> EmptyResponse:
        self.node.log.info("Clearing turtlesim.")
        background = self._background()
        with self.lock:
            self.world.clear(background)
        return EmptyResponse()

    def _reset(self, _req: Any) -> EmptyResponse:
        self.node.log.info("Resetting turtlesim.")
        background = self._background()
        with self.lock:
            for name in list(self.io):
                self._remove(name)
            turtle = self.world.reset(background)
            self._add(turtle.name)
        return EmptyResponse()

    def _spawn(self, req: Any) -> SpawnResponse:
        with self.lock:
            try:
                name = self.world.spawn(req.name, req.x, req.y, req.theta).name
            except TurtleError as exc:
                self._refuse(exc)
            self._add(name)
        return SpawnResponse(name)

    def _kill(self, req: Any) -> KillResponse:
        with self.lock:
            try:
                self.world.kill(req.name)
            except TurtleError as exc:
                self._refuse(exc)
            self._remove(req.name)
        return KillResponse()

    def _set_pen(self, name: str, req: Any) -> SetPenResponse:
        with self.lock:
            try:
                self.world.set_pen(name, req.r, req.g, req.b, req.width, bool(req.off))
            except TurtleError as exc:
                self._refuse(exc)
        return SetPenResponse()

    def _teleport_abs(self, name: str, req: Any) -> TeleportAbsoluteResponse:
        with self.lock:
            try:
                self.world.teleport_absolute(name, req.x, req.y, req.theta)
            except TurtleError as exc:
                self._refuse(exc)
        return TeleportAbsoluteResponse()

    def _teleport_rel(self, name: str, req: Any) -> TeleportRelativeResponse:
        with self.lock:
            try:
                self.world.teleport_relative(name, req.linear, req.angular)
            except TurtleError as exc:
                self._refuse(exc)
        return TeleportRelativeResponse()

    # -- the 16 ms loop --------------------------------------------------------------------------
    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="turtlesim-update", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)

    def _run(self) -> None:
        next_tick = time.monotonic()
        while not self._stop.is_set() and not self.node.is_shutdown:
            try:
                self.tick(time.monotonic())
            except Exception as exc:  # a bug in one tick must not freeze the simulation for good
                self.node.log.error("turtlesim update failed: %s: %s", type(exc).__name__, exc)
            next_tick += UPDATE_PERIOD
            delay = next_tick - time.monotonic()
            if delay < -UPDATE_PERIOD:  # fell behind (machine busy): do not try to catch up in a burst
                next_tick = time.monotonic()
                delay = 0.0
            self._stop.wait(max(delay, 0.0))

    def tick(self, now: float) -> None:
        """Advance the world to ``now`` and publish every turtle's pose and colour sensor."""
        with self.lock:
            self.world.step(now)
            out = []
            for name, turtle in self.world.turtles.items():
                io = self.io.get(name)
                if io is None:
                    continue
                pose = Pose(turtle.x, turtle.y, turtle.theta, turtle.linear_velocity, turtle.ang_z)
                out.append((io, pose, Color(*self.world.color_under(turtle))))
            if self.view is not None:
                self.view.publish()
        for io, pose, color in out:
            try:
                io.pose.publish(pose)
                io.color.publish(color)
            except ShutdownError:
                continue  # the turtle was killed between the step and the publish


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="turtlesim_node", description="The ROS turtlesim, drawn in a browser.")
    p.add_argument("--headless", action="store_true", help="no web view (same behaviour otherwise)")
    p.add_argument("--port", type=int, default=0, help="web view port (default: any free port)")
    p.add_argument("--host", default="127.0.0.1", help="web view address (default: localhost only)")
    p.add_argument("--no-browser", action="store_true", help="only print the view URL (no browser tab)")
    return p


#: starts a browser view of a running sim: ``(sim, options, ros_args) -> stop`` (None: it failed, logged)
ViewStarter = Callable[[TurtlesimNode, argparse.Namespace, list[str]], "Callable[[], None] | None"]


def main(argv: list[str] | None = None, view: ViewStarter | None = None) -> int:
    """Run the node. The browser view is not the simulator's business: the command that wants one
    (``turtlesim_node``, :mod:`ninjemys.web.turtlesim_view`) passes ``view``; without it, or with
    ``--headless``, the node runs the same with no web server."""
    argv = sys.argv[1:] if argv is None else argv
    ros_args = [a for a in argv if ":=" in a]
    options = _parser().parse_args([a for a in argv if ":=" not in a])
    parts: list[Any] = []  # the simulator, then the view's stop function

    def build(node: Node) -> int:
        sim = TurtlesimNode(node)
        parts.append(sim)
        if view is not None and not options.headless:
            stop_view = view(sim, options, ros_args)
            if stop_view is None:
                return 1
            parts.append(stop_view)
        sim.start()
        return 0

    try:
        return run_node("turtlesim", ros_args, build)
    finally:
        if parts:
            parts[0].stop()
        for stop in parts[1:]:
            stop()


console_main = entry(main)


if __name__ == "__main__":
    console_main()
