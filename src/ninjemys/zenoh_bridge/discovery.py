"""Discovery beacons, as zenoh-plugin-ros1 sends them: an empty put each second on a resource's
discovery key while it lives behind this bridge; a resource whose beacons stop for three periods is lost.

The Rust bridge also stops beaconing when it hears another bridge beacon the same key (ALOHA style);
beaconing always is compatible with it (receivers only count keys) and keeps this side simple.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from ninjemys.zenoh_bridge import keys
from ninjemys.zenoh_bridge.keys import Resource

_log = logging.getLogger("ninjemys.zenoh_bridge")

BEACON_PERIOD = 1.0
#: a remote resource is lost after this long without a beacon (the Rust bridge's 3 periods)
LOST_AFTER = 3 * BEACON_PERIOD


class Beacons:
    """The discovery keys this bridge announces, sent every period by one thread."""

    def __init__(self, session: Any, bridge_ns: str, period: float = BEACON_PERIOD) -> None:
        import zenoh

        self.session = session
        self.bridge_ns = bridge_ns
        self.period = period
        self._remote = zenoh.Locality.REMOTE
        self._keys: set[str] = set()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="zenoh-beacons", daemon=True)
        self._thread.start()

    def declare(self, kind: str, res: Resource) -> None:
        key = keys.discovery_key(res, kind, self.bridge_ns)
        with self._lock:
            new = key not in self._keys
            self._keys.add(key)
        if new:
            self._send(key)  # at once: a peer learns of it without waiting a period

    def undeclare(self, kind: str, res: Resource) -> None:
        with self._lock:
            self._keys.discard(keys.discovery_key(res, kind, self.bridge_ns))

    def _send(self, key: str) -> None:
        try:
            self.session.put(key, b"", allowed_destination=self._remote)
        except Exception as exc:  # a closing session: the next round or the shutdown settles it
            _log.debug("beacon %s: %s", key, exc)

    def _run(self) -> None:
        while not self._stop.wait(self.period):
            with self._lock:
                current = list(self._keys)
            for key in current:
                self._send(key)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)


class RemoteDirectory:
    """What other bridges in our namespace announce: ``{(kind, resource): last beacon time}``.

    ``on_change`` is called (from Zenoh's thread or the expiry check) when something appears or is lost.
    """

    def __init__(self, session: Any, bridge_ns: str, on_change: Callable[[], None]) -> None:
        import zenoh

        self._seen: dict[tuple[str, Resource], float] = {}
        self._lock = threading.Lock()
        self._on_change = on_change
        self._sub = session.declare_subscriber(
            keys.discovery_selector(bridge_ns), self._on_sample, allowed_origin=zenoh.Locality.REMOTE
        )

    def _on_sample(self, sample: Any) -> None:
        try:
            entry = keys.parse_discovery(str(sample.key_expr))
        except keys.KeyError_ as exc:
            _log.warning("ignored a discovery beacon: %s", exc)
            return
        with self._lock:
            new = entry not in self._seen
            self._seen[entry] = time.monotonic()
        if new:
            self._on_change()

    def expire(self) -> bool:
        """Forget resources whose beacons stopped; True when something was lost."""
        limit = time.monotonic() - LOST_AFTER
        with self._lock:
            lost = [e for e, t in self._seen.items() if t < limit]
            for e in lost:
                del self._seen[e]
        return bool(lost)

    def snapshot(self, kind: str) -> list[Resource]:
        with self._lock:
            return [res for (k, res) in self._seen if k == kind]

    def close(self) -> None:
        try:
            self._sub.undeclare()
        except Exception as exc:
            _log.debug("discovery subscriber: %s", exc)
