"""What a node has told the master, and re-telling it when the master forgets (a restart).

ROS 1 nodes register once; a restarted master knows nothing and the graph stays broken until every
node is restarted (the most cited ROS 1 complaint). Here the registrar keeps the node's
registrations, and a watchdog thread checks with one ``lookupNode`` call that the master still knows
this node whenever an idle TCP connection it keeps open to the master's port breaks (a restart is
noticed at once and costs nothing in steady state), every second while the master is down, and every
15 s as a fallback. When the master is back but has forgotten us (a new run), every
publisher, subscriber, service and parameter subscription is registered again; subscribers get
the current publisher list, publishers trigger ``publisherUpdate`` to their subscribers, so the
graph heals with no user action. If the master reports another URI for our name, a newer node took
it: we do not fight (the master shuts us down, as in ROS 1).

Registration calls made while the master is down are not errors: they are remembered and sent when
it comes back.

A restarted master learns the graph again one node at a time, so for a while its publisher lists
are short of the nodes that have not re-registered yet. Taken at their word (ROS 1's
``publisherUpdate`` semantics: drop what is not listed), they would cut live streams from healthy
publishers and lose the messages in flight until those publishers re-register (the soak test
found exactly that). So for :data:`SETTLE_PERIOD` seconds after a re-registration the node only
adds publishers and keeps its live connections (:meth:`Registrar.settling`); then it asks the
master once more for each topic's publishers and applies the full list, dropping what is really gone.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import partial

from ninjemys.errors import MasterError, MasterUnreachable, ShutdownError
from ninjemys.interrupt import wait_slice
from ninjemys.master.client import MasterClient
from ninjemys.net.addresses import split_uri
from ninjemys.node.transport import connect

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it

if TYPE_CHECKING:
    from ninjemys.node.context import NodeContext

_log = logging.getLogger(__name__)

#: Seconds between two checks while the master is unreachable (or no link to it could be opened).
WATCH_PERIOD = 1.0
#: Seconds between two checks while the link to the master is up (a broken link triggers one at once).
IDLE_CHECK_PERIOD = 15.0
#: Seconds after a re-registration during which publisher lists only add (the new master's view is
#: still filling in); long enough for every other node to notice the restart and register again.
SETTLE_PERIOD = 10.0


#: Seconds a shutting-down node's unregistration waits for a call of the same name still in flight
#: (a user thread's registration with a master that hangs): shutdown stays prompt.
_SHUTDOWN_TURN = 2.0

#: (kind, name): the registration calls of one publisher topic, subscriber topic or service
TurnKey = tuple[str, str]


class Turns:
    """Per-name order of a node's registration calls, as the node's tables changed.

    The node changes its tables under its own lock, but makes the master call after releasing it
    (never across a master call). So an unsubscribe on one thread and a subscribe of the same topic on
    another could reach the master in the opposite order: the master would then forget a live
    subscription. A ticket taken under the node's lock fixes each call's place; :meth:`turn` waits
    until the calls of the earlier tickets of that name are done. Names never wait on each other.
    """

    def __init__(self) -> None:
        self._cond = threading.Condition(threading.Lock())
        self._next: dict[TurnKey, int] = {}  # the ticket the next take() hands out
        self._serving: dict[TurnKey, int] = {}  # the ticket whose call may run now
        self._finished: set[tuple[TurnKey, int]] = set()  # done out of order (given up while waiting)

    def take(self, kind: str, name: str) -> tuple[TurnKey, int]:
        """A place in line for one call about ``name`` (take it while the change is made)."""
        key = (kind, name)
        with self._cond:
            ticket = self._next.get(key, 0)
            self._next[key] = ticket + 1
        return key, ticket

    def waiting(self, kind: str, name: str) -> int:
        """How many tickets of ``name`` are taken and not done (for tests and diagnostics)."""
        key = (kind, name)
        with self._cond:
            return self._next.get(key, 0) - self._serving.get(key, 0)

    def wait(self, place: tuple[TurnKey, int], limit: float | None = None) -> bool:
        """Block until every earlier ticket of the same name is done (True), or ``limit`` seconds
        have passed (False: the caller goes out of turn)."""
        key, ticket = place
        deadline = None if limit is None else time.monotonic() + limit
        with self._cond:
            while self._serving.get(key, 0) != ticket:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    return False
                self._cond.wait(wait_slice(left))
        return True

    def done(self, place: tuple[TurnKey, int]) -> None:
        """The call of ``place`` is over, failed, or was given up while waiting: let the next go."""
        key, ticket = place
        with self._cond:
            self._finished.add(place)
            serving = self._serving.get(key, 0)
            while (key, serving) in self._finished:
                self._finished.discard((key, serving))
                serving += 1
            if self._next.get(key) == serving:  # nobody in line: forget the name
                del self._next[key]
                self._serving.pop(key, None)
            else:
                self._serving[key] = serving
            self._cond.notify_all()


class Registrar:
    """Registrations of one node, with a watchdog that restores them on a new master.

    Each add/remove call takes a ``place`` from :attr:`turns`, given by the node when it made the
    change under its lock, or taken on entry; the call runs when its turn comes (:class:`Turns`)."""

    def __init__(self, node: NodeContext) -> None:
        self.node = node
        self.publications: dict[str, str] = {}
        self.subscriptions: dict[str, str] = {}
        self.services: dict[str, str] = {}
        self.param_keys: set[str] = set()
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._master_down = False
        # the watchdog has its own client (short timeout) so it never waits behind a user call
        self._probe = MasterClient(node.master_uri, node.name, timeout=2.0)
        self._thread: threading.Thread | None = None
        self._link: socket.socket | None = None
        self._link_up = False
        self._link_lost = threading.Event()
        self._settle_deadline = 0.0  # monotonic end of the settling window; 0: none pending
        #: the order of each name's registration calls (see :class:`Turns`)
        self.turns = Turns()

    def start(self) -> None:
        self._thread = threading.Thread(target=self._watch, name=f"reg:{self.node.name}", daemon=True)
        self._thread.start()

    # -- registrations (user threads) ------------------------------------------------------------

    def _try(self, what: str, fn: Callable[[], object]) -> object | None:
        try:
            return fn()
        except MasterUnreachable as exc:
            if not self._master_down:
                # rospy's words (ours re-registers by itself when the master comes back)
                _log.warning(
                    "Unable to register with master node [%s]: master may not be running yet. Will keep trying.",
                    self.node.master_uri,
                )
                _log.debug("%s: %s", what, exc)
            self._master_down = True
            return None
        except MasterError as exc:
            if getattr(self.node, "strict_names", True) or getattr(exc, "status", None) is None:
                raise
            # rospy's leniency (a node named "a b" registers its ~get_loggers as "/a b/get_loggers"):
            # the master refuses, rospy logs FATAL in its own words and the node runs on without it.
            self._refused(what, str(getattr(exc, "status", exc)))
            return None

    def _refused(self, what: str, status: str) -> None:
        kind, _, name = what.partition(" ")
        noun = {"publisher": "publication", "subscriber": "subscription"}.get(kind, kind)
        log = getattr(self.node, "log", None)
        text = f"unable to register {noun} [{name}] with master: {status}"
        if log is None:
            _log.critical("%s", text)
        else:
            from ninjemys.node.log import FATAL

            log.log(FATAL, "%s", text)

    @contextmanager
    def _turn(
        self, kind: str, name: str, place: tuple[TurnKey, int] | None, limit: float | None = None
    ) -> Iterator[None]:
        """Run the body as the call of ``place`` (a new place in line when None), after waiting at
        most ``limit`` seconds for the earlier ones."""
        if place is None:
            place = self.turns.take(kind, name)
        try:
            self.turns.wait(place, limit)
            yield
        finally:
            self.turns.done(place)

    def add_publisher(self, topic: str, type_name: str, place: tuple[TurnKey, int] | None = None) -> None:
        with self._turn("pub", topic, place):
            with self._lock:
                self.publications[topic] = type_name
            self._try(
                f"publisher {topic}",
                lambda: self.node.master.register_publisher(topic, type_name, self.node.uri),
            )

    def add_subscriber(
        self, topic: str, type_name: str, place: tuple[TurnKey, int] | None = None
    ) -> list[str] | None:
        with self._turn("sub", topic, place):
            with self._lock:
                self.subscriptions[topic] = type_name
            result = self._try(
                f"subscriber {topic}",
                lambda: self.node.master.register_subscriber(topic, type_name, self.node.uri),
            )
        return list(result) if isinstance(result, list) else None

    def add_service(self, name: str, service_uri: str, place: tuple[TurnKey, int] | None = None) -> None:
        with self._turn("srv", name, place):
            with self._lock:
                self.services[name] = service_uri
            self._try(
                f"service {name}",
                lambda: self.node.master.register_service(name, service_uri, self.node.uri),
            )

    def add_param_subscription(self, key: str) -> object | None:
        with self._lock:
            self.param_keys.add(key)
        return self._try(f"param {key}", lambda: self.node.master.subscribe_param(self.node.uri, key))

    def remove_publisher(
        self, topic: str, client: MasterClient | None = None, place: tuple[TurnKey, int] | None = None
    ) -> None:
        with self._turn("pub", topic, place, _SHUTDOWN_TURN if client is not None else None):
            with self._lock:
                self.publications.pop(topic, None)
            self._quiet(lambda c: c.unregister_publisher(topic, self.node.uri), client)

    def remove_subscriber(
        self, topic: str, client: MasterClient | None = None, place: tuple[TurnKey, int] | None = None
    ) -> None:
        with self._turn("sub", topic, place, _SHUTDOWN_TURN if client is not None else None):
            with self._lock:
                self.subscriptions.pop(topic, None)
            self._quiet(lambda c: c.unregister_subscriber(topic, self.node.uri), client)

    def remove_service(
        self, name: str, client: MasterClient | None = None, place: tuple[TurnKey, int] | None = None
    ) -> None:
        with self._turn("srv", name, place, _SHUTDOWN_TURN if client is not None else None):
            with self._lock:
                uri = self.services.pop(name, None)
            if uri is not None:
                self._quiet(lambda c: c.unregister_service(name, uri), client)

    def _quiet(self, fn: Callable[[MasterClient], object], client: MasterClient | None) -> None:
        if self._master_down and client is not None:
            return  # shutting down with no master: do not wait once per registration
        try:
            fn(client or self.node.master)
        except MasterUnreachable as exc:
            self._master_down = True
            _log.debug("unregister: %s", exc)
        except MasterError as exc:
            _log.debug("unregister: %s", exc)

    # -- watchdog --------------------------------------------------------------------------------

    def settling(self) -> bool:
        """True while a restarted master may still be missing other nodes' registrations: publisher
        lists from it must not cut live connections (see the module's docstring)."""
        return self._settle_deadline > 0.0 and time.monotonic() < self._settle_deadline

    def _watch(self) -> None:
        """Check the master when the link to it breaks (instantly), every WATCH_PERIOD while it is
        down, and every IDLE_CHECK_PERIOD otherwise (in case no link could be kept); end a settling
        window when it is due."""
        self._spawn_link()
        while not self._stop.is_set():
            period = WATCH_PERIOD if self._master_down or not self._link_up else IDLE_CHECK_PERIOD
            if self._settle_deadline:
                period = max(0.0, min(period, self._settle_deadline - time.monotonic()))
            self._link_lost.wait(period)
            self._link_lost.clear()
            if self._stop.is_set():
                return
            if self._settle_deadline and time.monotonic() >= self._settle_deadline and not self._master_down:
                self._settle()
            self._check()
            if not self._master_down and not self._link_up:
                self._spawn_link()

    def _spawn_link(self) -> None:
        try:
            self.node.runtime.spawn(self._open_link())
        except ShutdownError:
            self._stop.set()

    def _check(self) -> None:
        with self._lock:
            empty = not (self.publications or self.subscriptions or self.services or self.param_keys)
        if empty and not self._master_down:
            return
        try:
            known = self._probe.lookup_node(self.node.name)
        except MasterUnreachable:
            self._master_down = True
            return
        except MasterError:
            known = None  # "unknown node": a new master
        if known == self.node.uri and not self._master_down:
            return
        if known not in (None, self.node.uri):
            return  # another node took our name; the master shuts us down
        if not self._stop.is_set():
            self._reregister()

    # -- the link: an idle TCP connection to the master whose end tells us it went away -----------

    async def _open_link(self) -> None:
        """On the loop: connect to the master's port and watch the socket (no request is sent)."""
        if self._link is not None or self._stop.is_set():
            return
        loop = self.node.runtime.loop
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setblocking(False)
        try:
            host, port = split_uri(self.node.master_uri)
            await connect(sock, (host, port), timeout=2.0)
        except (OSError, ValueError, TimeoutError):
            sock.close()
            return
        if self._stop.is_set():
            sock.close()
            return
        self._link = sock
        self._link_up = True
        loop.add_reader(sock.fileno(), self._on_link_event)

    def _on_link_event(self) -> None:
        """The master closed our idle connection (it died, restarted, or timed us out): check it."""
        self._close_link()
        self._link_lost.set()

    def _close_link(self) -> None:
        sock, self._link = self._link, None
        self._link_up = False
        if sock is not None:
            try:
                self.node.runtime.loop.remove_reader(sock.fileno())
            except (ValueError, OSError):
                pass
            sock.close()

    def _reregister(self) -> None:
        with self._lock:
            pubs = dict(self.publications)
            subs = dict(self.subscriptions)
            srvs = dict(self.services)
            keys = set(self.param_keys)
        if pubs or subs or srvs or keys:
            _log.info(
                "master at %s does not know %s: registering again", self.node.master_uri, self.node.name
            )
        master, uri = self._probe, self.node.uri
        if subs:
            self._settle_deadline = time.monotonic() + SETTLE_PERIOD

        def again(fn: Callable[[], object]) -> object | None:
            try:
                return fn()
            except MasterUnreachable:
                raise
            except MasterError as exc:  # a name this master refuses (rospy's leniency): skip it
                _log.debug("re-registration: %s", exc)
                return None

        try:
            # each in its name's turn, and only if still registered then: an unregistration made
            # meanwhile is not undone (see Turns)
            for topic, type_name in pubs.items():
                with self._turn("pub", topic, None):
                    if topic in self.publications:
                        again(partial(master.register_publisher, topic, type_name, uri))
            for topic, type_name in subs.items():
                with self._turn("sub", topic, None):
                    if topic not in self.subscriptions:
                        continue
                    updates = self.node.publisher_updates(topic)  # an update newer than the answer wins
                    publishers = again(partial(master.register_subscriber, topic, type_name, uri))
                if isinstance(publishers, list):
                    self.node.publisher_update(topic, list(publishers), updates)
            for name, service_uri in srvs.items():
                with self._turn("srv", name, None):
                    if self.services.get(name) == service_uri:
                        again(partial(master.register_service, name, service_uri, uri))
            for key in keys:
                again(partial(master.subscribe_param, uri, key))
        except MasterError as exc:
            _log.info("re-registration interrupted: %s", exc)
            self._master_down = True
            return
        self._master_down = False

    def _settle(self) -> None:
        """The settling window is over: the full publisher list of every topic, applied as given."""
        self._settle_deadline = 0.0
        with self._lock:
            subs = dict(self.subscriptions)
        try:
            for topic, type_name in subs.items():
                with self._turn("sub", topic, None):
                    if topic not in self.subscriptions:
                        continue
                    updates = self.node.publisher_updates(topic)
                    publishers = self._probe.register_subscriber(topic, type_name, self.node.uri)
                if isinstance(publishers, list):
                    self.node.publisher_update(topic, list(publishers), updates)
        except MasterUnreachable:
            self._master_down = True  # the next re-registration opens a new window
        except MasterError as exc:
            _log.debug("settling: %s", exc)

    def stop(self) -> None:
        self._stop.set()
        self._link_lost.set()
        if self.node.runtime.alive:
            self.node.runtime.call_soon(self._close_link)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(3.0)
        self._probe.close()
