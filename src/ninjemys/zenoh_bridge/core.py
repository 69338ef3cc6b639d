"""The bridge: one Zenoh session, one ROS node, and a loop that makes the bridges match the graphs.

Each poll (``--ros_master_polling_interval``, sooner when a remote beacon appears) reads the local
master, decides per resource and bridging mode which bridges should exist, opens the missing ones
and closes the rest. When the master cannot be read, every bridge is closed (as the Rust bridge
does) and the next successful read rebuilds them: a restarted master or bridge heals the graph.
"""

from __future__ import annotations

import functools
import logging
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Literal

from ninjemys.errors import NinjemysError
from ninjemys.net import auth
from ninjemys.net.auth import Credentials
from ninjemys.zenoh_bridge import access, keys
from ninjemys.zenoh_bridge.discovery import Beacons, RemoteDirectory
from ninjemys.zenoh_bridge.keys import Resource
from ninjemys.zenoh_bridge.options import AUTO, DISABLED, LAZY_AUTO, BridgeOptions
from ninjemys.zenoh_bridge.relays import RosToZenoh, ServiceToZenoh, ZenohToRos, ZenohToService
from ninjemys.zenoh_bridge.rosside import GraphState, LocalGraph

_log = logging.getLogger("ninjemys.zenoh_bridge")

Key = tuple[str, Resource]


class ZenohSessionError(NinjemysError):
    """The Zenoh session could not be opened (bad configuration, an endpoint that cannot listen)."""


def open_session(options: BridgeOptions, creds: Credentials | None | Literal["env"] = "env") -> Any:
    """A Zenoh session configured from the command line (over ``--config`` when given). With the
    graph's authentication on (``creds``: the process's by default), Zenoh's user/password
    authentication from the same secret (zenoh_bridge.access)."""
    import json

    import zenoh

    if creds == "env":
        creds = auth.credentials()
    try:
        config = zenoh.Config.from_file(options.config_file) if options.config_file else zenoh.Config()
        for key, value in options.zenoh_config_json().items():
            config.insert_json5(key, json.dumps(value))
        with access.usrpwd_settings(creds, options.node_name()) as settings:
            for key, value in settings.items():
                config.insert_json5(key, json.dumps(value))
            return zenoh.open(config)
    except zenoh.ZError as exc:
        raise ZenohSessionError(f"cannot open the Zenoh session ({_endpoints(options)}): {exc}") from None


def _endpoints(options: BridgeOptions) -> str:
    parts = [f"listen {e}" for e in options.listen] + [f"connect {e}" for e in options.connect]
    return ", ".join(parts) or f"mode {options.mode}"


class ZenohBridge:
    """Runs until :meth:`close`; ``status`` (if given) is called with a line each time the bridges change."""

    def __init__(self, options: BridgeOptions, status: Callable[[str], None] | None = None) -> None:
        from ninjemys.node import Node

        self.options = options
        self._status = status or (lambda line: _log.info("%s", line))
        self.session = open_session(options)
        self._wake = threading.Event()
        self._stop = threading.Event()
        self.bridges: dict[Key, Any] = {}
        self._pool = ThreadPoolExecutor(max_workers=8, thread_name_prefix="zenoh-srv")
        try:
            self.node = Node(
                options.ros_name,
                namespace=options.ros_namespace,
                master_uri=options.ros_master_uri,
                rosout=False,
                logger_services=False,
                default_clock=False,
            )
            self.graph = LocalGraph(self.node.master, self.node.name)
            self.beacons = Beacons(self.session, options.bridge_namespace)
            self.remote = RemoteDirectory(self.session, options.bridge_namespace, self._wake.set)
        except BaseException:
            self.session.close()
            raise
        self._ros_ok: bool | None = None
        self._announced: set[Key] = set()
        self._refused: set[Key] = set()
        self._step_lock = threading.Lock()

    # -- the loop -------------------------------------------------------------------------------

    def run(self) -> None:
        """Poll and reconcile until :meth:`close` is called."""
        while not self._stop.is_set():
            with self._step_lock:
                if self._stop.is_set():
                    break
                changed = self.step()
            interval = self.options.polling_interval / (2 if changed else 1)
            self._wake.wait(interval)
            self._wake.clear()

    def step(self) -> bool:
        """One poll; True when bridges were opened or closed."""
        self.remote.expire()
        try:
            state = self.graph.read()
        except (OSError, NinjemysError) as exc:
            changed = bool(self.bridges)
            self._reconcile({}, set())
            if self._ros_ok is not False:
                self._status(f"ROS master {self.options.ros_master_uri} unreachable: {exc}; bridges closed")
            self._ros_ok = False
            return changed
        if self._ros_ok is not True:
            self._status(f"ROS master {self.options.ros_master_uri} reached")
        self._ros_ok = True
        wanted, announced = self.plan(state)
        return self._reconcile(wanted, announced)

    def plan(self, state: GraphState) -> tuple[dict[Key, Callable[[], Any]], set[Key]]:
        """The bridges that should exist (key -> how to open it) and the beacons to send.

        As in zenoh-plugin-ros1, a resource is wanted here (a local publisher, subscriber or service)
        and/or by another bridge (its complement announced: a remote subscriber, publisher or client).
        ``auto`` bridges when either holds, ``lazy_auto`` when both do, ``disabled`` never, and only
        local resources are announced. A remote service is provided here when client bridging is
        ``auto`` for it and no local node provides it already.
        """
        o, node, session, ns = self.options, self.node, self.session, self.options.bridge_namespace
        wanted: dict[Key, Callable[[], Any]] = {}
        announced: set[Key] = set()

        def consider(kind: str, option: str, local: set[Resource], remote: set[Resource],
                     make: Callable[[Resource], Any]) -> None:  # fmt: skip
            for res in local | remote:
                mode = o.mode_for(option, res.name)
                if mode == DISABLED:
                    continue
                here, there = res in local, res in remote
                if here:
                    announced.add((kind, res))
                if (here and there) or (mode == AUTO and (here or there)):
                    wanted[(kind, res)] = functools.partial(make, res)

        consider(keys.PUB, "publisher", state.publishers, set(self.remote.snapshot(keys.SUB)),
                 lambda r: RosToZenoh(node, session, r, ns, self._definition(r)))  # fmt: skip
        consider(keys.SUB, "subscriber", state.subscribers, set(self.remote.snapshot(keys.PUB)),
                 lambda r: ZenohToRos(node, session, r, ns))  # fmt: skip
        # a service is bridged only where it exists: a queryable for a service nobody provides answers nothing
        consider(keys.SRV, "service", state.services, set(),
                 lambda r: ServiceToZenoh(node, session, r, ns, self._pool))  # fmt: skip
        if o.modes["service"] == LAZY_AUTO or LAZY_AUTO in o.custom_modes["service"].values():
            remote_cls = set(self.remote.snapshot(keys.CL))
            for res in state.services:
                if o.mode_for("service", res.name) == LAZY_AUTO and res not in remote_cls:
                    wanted.pop((keys.SRV, res), None)
        local_services = {r.name for r in state.services}
        for res in self.remote.snapshot(keys.SRV):
            if res.name not in local_services and o.mode_for("client", res.name) == AUTO:
                announced.add((keys.CL, res))
                wanted[(keys.CL, res)] = functools.partial(ZenohToService, node, session, res, ns)
        return wanted, announced

    def _definition(self, res: Resource) -> str:
        header = self.graph.publisher_headers.get(res.name, {})
        return header.get("message_definition", "") if header.get("md5sum") == res.md5 else ""

    def _reconcile(self, wanted: dict[Key, Callable[[], Any]], announced: set[Key]) -> bool:
        import zenoh

        changed = False
        self._refused &= set(wanted)
        for key in list(self.bridges):
            if key not in wanted:
                self._close_bridge(key)
                changed = True
        for key, make in wanted.items():
            if key in self.bridges:
                continue
            kind, res = key
            try:
                self.bridges[key] = make()
            except (OSError, NinjemysError, zenoh.ZError) as exc:
                # tried again each poll (the conflict may clear), said once
                if key not in self._refused:
                    self._refused.add(key)
                    self._status(f"cannot bridge {kind} {res.name} [{res.datatype}]: {exc}")
                continue
            self._refused.discard(key)
            changed = True
            self._status(
                f"bridged {kind} {res.name} [{res.datatype}] as {keys.data_key(res, self.options.bridge_namespace)}"
            )
        for kind, res in announced:
            self.beacons.declare(kind, res)
        for kind, res in self._announced - announced:
            self.beacons.undeclare(kind, res)
        self._announced = announced
        return changed

    def _close_bridge(self, key: Key) -> None:
        bridge = self.bridges.pop(key)
        try:
            bridge.close()
        except Exception as exc:  # a half-closed session or node: closing goes on with the rest
            _log.debug("closing %s: %s", key, exc)
        self._status(f"unbridged {key[0]} {key[1].name}")

    def stop(self) -> None:
        """Make :meth:`run` return after the poll under way (safe from a signal handler)."""
        self._stop.set()
        self._wake.set()

    def close(self) -> None:
        """Stop the loop, close the bridges, the node and the session."""
        self.stop()
        with self._step_lock:  # a poll under way finishes first: nothing opens on a closing session
            self._teardown()

    def _teardown(self) -> None:
        for key in list(self.bridges):
            self._close_bridge(key)
        self.beacons.close()
        self.remote.close()
        self._pool.shutdown(wait=False, cancel_futures=True)
        self.node.shutdown("zenoh bridge closed")
        self.session.close()
