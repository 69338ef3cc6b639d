"""``tf2_web_republisher``: the transforms a web client asks for, relative to one frame, at a set rate.

Web TF clients use one of its two interfaces:

- the service ``/republish_tfs`` (``tf2_web_republisher/RepublishTFs``; roslibjs' and roslibpy's
  ``TFClient`` by default): the answer names a new latched topic ``/tf_repub_<n>`` carrying
  ``tf2_web_republisher/TFArray``; a topic nobody listens to for ``timeout`` is withdrawn;
- the action ``/tf2_web_republisher`` (``tf2_web_republisher/TFSubscription``; older roslibjs): the
  transforms come as the goal's feedback until the client cancels it.

Either way each source frame is expressed in ``target_frame`` at ``rate`` Hz, and re-sent only when
it moved by more than ``trans_thres`` (metres) or turned by more than ``angular_thres`` (radians).
The buffer is tf2's (:mod:`ninjemys.tf2`), fed by a listener on ``/tf`` and ``/tf_static``.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import math
import sys
import threading
import time
from typing import Any

from ninjemys.actionlib.server import ActionServer
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node

log = logging.getLogger(__name__)


class _Client:
    """One subscription: a ``/tf_repub_<n>`` topic (``pub``) or an action goal (``goal``)."""

    def __init__(self, key: str, req: Any, pub: Any = None, goal: Any = None) -> None:
        self.key = key
        self.pub = pub
        self.goal = goal
        self.cancelled = False
        self.sources = [f.lstrip("/") for f in req.source_frames]
        self.target = req.target_frame.lstrip("/")
        self.angular_thres = float(req.angular_thres)
        self.trans_thres = float(req.trans_thres)
        self.period = 1.0 / req.rate if req.rate > 0 else 0.1
        timeout = getattr(req, "timeout", None)  # the action's goal has none: it lasts until cancelled
        self.timeout = 0.0 if timeout is None else timeout.to_sec()
        self.last: dict[str, tuple[float, ...]] = {}
        self.unheard_since: float | None = None


def _moved(old: tuple[float, ...], new: tuple[float, ...], trans: float, angular: float) -> bool:
    dx, dy, dz = new[0] - old[0], new[1] - old[1], new[2] - old[2]
    if math.sqrt(dx * dx + dy * dy + dz * dz) > trans:
        return True
    dot = abs(sum(a * b for a, b in zip(old[3:], new[3:], strict=True)))
    return 2.0 * math.acos(min(1.0, dot)) > angular


class TFRepublisher:
    """The ``/republish_tfs`` service (its ``/tf_repub_<n>`` topics) and the ``/tf2_web_republisher``
    action on ``node``."""

    def __init__(self, node: Node, buffer: Any | None = None) -> None:
        from ninjemys.tf2.buffer import Buffer
        from ninjemys.tf2.node import TransformListener

        self.node = node
        self.buffer = buffer if buffer is not None else Buffer()
        self._listener = TransformListener(node, self.buffer) if buffer is None else None
        self._array = get_message_class("tf2_web_republisher/TFArray")
        self._stamped = get_message_class("geometry_msgs/TransformStamped")
        self._ids = itertools.count()
        self._clients: dict[str, _Client] = {}
        self._due: list[tuple[float, int, str]] = []
        self._order = itertools.count()
        self._wake = threading.Condition()
        self._stop = False
        self._feedback = get_message_class("tf2_web_republisher/TFSubscriptionFeedback")
        self.service = node.service(
            "republish_tfs", get_service_class("tf2_web_republisher/RepublishTFs"), self._republish
        )
        self.action = ActionServer(
            node,
            "tf2_web_republisher",
            get_message_class("tf2_web_republisher/TFSubscriptionAction"),
            self._goal,
            self._cancel,
        )
        self.action.start()
        self._thread = threading.Thread(target=self._run, name="tf2_web_republisher", daemon=True)
        self._thread.start()

    def _add(self, client: _Client) -> None:
        with self._wake:
            self._clients[client.key] = client
            heapq.heappush(self._due, (time.monotonic(), next(self._order), client.key))
            self._wake.notify()
        log.info("tf2_web_republisher: %s for %s in %s", client.key, client.sources, client.target)

    def _republish(self, req: Any) -> Any:
        topic = f"/tf_repub_{next(self._ids)}"
        pub = self.node.publisher(topic, self._array, queue_size=10, latch=True)
        self._add(_Client(topic, req, pub=pub))
        return {"topic_name": topic}

    def _goal(self, handle: Any) -> None:
        handle.set_accepted()
        self._add(_Client(f"goal:{handle.get_goal_id().id}", handle.get_goal(), goal=handle))

    def _cancel(self, handle: Any) -> None:
        with self._wake:
            client = self._clients.get(f"goal:{handle.get_goal_id().id}")
            if client is not None:
                client.cancelled = True
        handle.set_canceled()

    def _run(self) -> None:
        while True:
            with self._wake:
                while not self._stop and (not self._due or self._due[0][0] > time.monotonic()):
                    self._wake.wait(None if not self._due else self._due[0][0] - time.monotonic())
                if self._stop:
                    return
                _, _, key = heapq.heappop(self._due)
                client = self._clients.get(key)
            if client is None:
                continue
            if self._expired(client):
                with self._wake:
                    self._clients.pop(key, None)
                if client.pub is not None:
                    client.pub.unregister()
                log.info("tf2_web_republisher: %s ended (cancelled, or no subscriber)", key)
                continue
            self._send(client)
            with self._wake:
                heapq.heappush(self._due, (time.monotonic() + client.period, next(self._order), key))

    def _expired(self, client: _Client) -> bool:
        if client.goal is not None:
            return client.cancelled
        if client.pub.get_num_connections() > 0 or client.timeout <= 0:
            client.unheard_since = None
            return False
        now = time.monotonic()
        if client.unheard_since is None:
            client.unheard_since = now
        return now - client.unheard_since > client.timeout

    def _send(self, client: _Client) -> None:
        out = []
        for source in client.sources:
            try:
                t = self.buffer.lookup_transform(client.target, source, 0)
            except Exception:  # not (yet) connected: tf2_web_republisher skips it quietly
                continue
            tr, rot = t.transform.translation, t.transform.rotation
            pose = (tr.x, tr.y, tr.z, rot.x, rot.y, rot.z, rot.w)
            old = client.last.get(source)
            if old is not None and not _moved(old, pose, client.trans_thres, client.angular_thres):
                continue
            client.last[source] = pose
            t.header.frame_id = client.target
            t.child_frame_id = source
            out.append(t)
        if not out:
            return
        if client.goal is not None:
            client.goal.publish_feedback(self._feedback(transforms=out))
        else:
            client.pub.publish(self._array(transforms=out))

    def shutdown(self) -> None:
        with self._wake:
            self._stop = True
            self._wake.notify()
        self._thread.join(2.0)
        self.service.shutdown()
        self.action.stop()
        if self._listener is not None:
            self._listener.unregister()


def main(argv: list[str] | None = None) -> int:
    """``rosrun tf2_web_republisher tf2_web_republisher``."""
    from ninjemys.node.cli_args import parse_args

    args = parse_args([sys.argv[0], *(sys.argv[1:] if argv is None else argv)])
    name = args.node_name("tf2_web_republisher")
    node = Node(
        name,
        namespace=args.namespace,
        remappings=args.resolved_remappings(args.full_name(name)),
        master_uri=args.master_uri,
        params=args.private_params,
    )
    republisher = TFRepublisher(node)
    try:
        node.spin()
    except KeyboardInterrupt:
        pass
    finally:
        republisher.shutdown()
        node.shutdown("tf2_web_republisher exiting")
    return 0
