"""The action server: ROS 1's protocol on ``<ns>/{goal,cancel,status,feedback,result}``.

One :class:`StatusTracker` per goal the server knows; a :class:`ServerGoalHandle` is the user's view of
it and the only way to move it through the goal state machine::

    PENDING --accept--> ACTIVE --succeed/abort--> SUCCEEDED/ABORTED
       |  \\--reject--> REJECTED    |--cancel request--> PREEMPTING --cancelled--> PREEMPTED
       |--cancel request--> RECALLING --accept--> PREEMPTING; --cancelled--> RECALLED

Cancel rules (a GoalID on ``cancel``): an empty id with a zero stamp cancels every goal; a matching id
cancels that goal; a non-zero stamp cancels every goal stamped at or before it. A cancel naming an id
the server has not seen yet is remembered (a RECALLING entry), so when that goal arrives after its
own cancel (topics are not ordered with each other) it is recalled at once; a goal stamped at or
before the latest cancel stamp is cancelled on arrival.

Status (``GoalStatusArray``, latched) goes out at ``actionlib_status_frequency`` (5 Hz) and after every
transition. Terminal goals stay in it for ``status_list_timeout`` (5 s) so late clients still see
them. Unlike ROS 1, transitions in a burst do not each serialize the whole list: a transition
publishes at once unless one did less than ``MERGE_INTERVAL`` ago, and then the status thread sends
one list for all the transitions meanwhile, so a thousand goals a second do not publish two thousand
growing arrays a second.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Iterator, MutableSequence

from ninjemys.actionlib import states
from ninjemys.actionlib.common import (
    ActionTypes,
    goal_status_array_class,
    goal_status_class,
    resolve_clock,
    resolve_log,
    stamp_of,
)
from ninjemys.actionlib.goal_id import GoalIDGenerator
from ninjemys.node.clock import Clock
from ninjemys.node.timers import Timer
from ninjemys.rostime import Duration, Time

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

#: seconds between two status messages caused by transitions (the periodic ones are separate)
MERGE_INTERVAL = 0.1

_ZERO = Time()


class StatusTracker:
    """What the server knows about one goal: its status (id, stamp, code, text) and the goal itself."""

    __slots__ = ("goal", "status", "destruction_time", "handle_tracker")

    def __init__(self, status: Any, goal: Any = None) -> None:
        self.goal = goal  # the ActionGoal message, None for a remembered cancel
        self.status = status
        #: when the goal reached a terminal state (zero while it is live); it leaves the list
        #: ``status_list_timeout`` later
        self.destruction_time = _ZERO
        self.handle_tracker = None  # ROS 1's attribute, kept for code that inspects trackers

    @property
    def handle_destruction_time(self) -> Time:
        """ROS 1's name for :attr:`destruction_time` (HandleTrackerDeleter sets it)."""
        return self.destruction_time

    @handle_destruction_time.setter
    def handle_destruction_time(self, stamp: Time) -> None:
        self.destruction_time = stamp


class StatusList(MutableSequence):
    """ROS 1's ``ActionServer.status_list``: the server's trackers in arrival order, live.

    Code written for ROS 1 edits it directly (its own tests "lose" a goal by deleting its tracker); an
    edit here changes the goals the server lists, under the server's lock.
    """

    def __init__(self, server: ActionServer) -> None:
        self._server = server

    def _items(self) -> list[StatusTracker]:
        return list(self._server.trackers.values())

    def _replace(self, items: Iterable[StatusTracker]) -> None:
        # transitions still waiting for a merged status publication go out first: clients must see
        # the goals as they were before the edit (ROS 1 publishes every transition at once)
        self._server.flush_status()
        trackers = self._server.trackers
        trackers.clear()
        trackers.update((t.status.goal_id.id, t) for t in items)

    def __len__(self) -> int:
        return len(self._server.trackers)

    def __iter__(self) -> Iterator[StatusTracker]:
        with self._server.lock:
            return iter(self._items())  # a snapshot: the loop may edit the list

    def __getitem__(self, i: Any) -> Any:
        with self._server.lock:
            return self._items()[i]

    def __setitem__(self, i: Any, value: Any) -> None:
        with self._server.lock:
            items = self._items()
            items[i] = value
            self._replace(items)

    def __delitem__(self, i: Any) -> None:
        with self._server.lock:
            items = self._items()
            del items[i]
            self._replace(items)

    def insert(self, index: int, value: StatusTracker) -> None:
        with self._server.lock:
            items = self._items()
            items.insert(index, value)
            self._replace(items)

    def __repr__(self) -> str:
        return repr(self._items())


class ServerGoalHandle:
    """The user's handle on one goal: accept, reject, succeed, abort, cancel, publish feedback.

    Every transition that ROS 1 refuses is refused here too, with one error line naming the goal
    and the state it is in; the goal is left as it was.
    """

    def __init__(
        self,
        status_tracker: StatusTracker | None = None,
        action_server: ActionServer | None = None,
        handle_tracker: Any = None,
    ) -> None:
        self.status_tracker = status_tracker
        self.action_server = action_server
        self.handle_tracker = handle_tracker  # ROS 1's signature; nothing here needs it
        self.goal = status_tracker.goal if status_tracker is not None else None

    # -- accessors ---------------------------------------------------------------------------------

    def get_goal(self) -> Any:
        """The goal message (FooGoal), or None for an empty handle."""
        return self.goal.goal if self.goal is not None else None

    def _bound(self, what: str) -> tuple[StatusTracker, ActionServer] | None:
        """The goal's tracker and server; None (and one error line) for an empty handle."""
        if self.goal is None or self.status_tracker is None or self.action_server is None:
            self._log_empty(what)
            return None
        return self.status_tracker, self.action_server

    def get_goal_id(self) -> Any:
        bound = self._bound("get a goal id of")
        return goal_status_class()().goal_id if bound is None else bound[0].status.goal_id

    def get_goal_status(self) -> Any:
        bound = self._bound("get the goal status of")
        return goal_status_class()() if bound is None else bound[0].status

    def get_default_result(self) -> Any:
        assert self.action_server is not None, "an empty ServerGoalHandle has no action"
        return self.action_server.types.result()

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ServerGoalHandle) or self.goal is None or other.goal is None:
            return False
        return self.get_goal_id().id == other.get_goal_id().id

    def __ne__(self, other: object) -> bool:
        return not self == other

    def __hash__(self) -> int:
        return hash(self.get_goal_id().id) if self.goal is not None else 0

    def __repr__(self) -> str:
        if self.goal is None or self.status_tracker is None:
            return "ServerGoalHandle(empty)"
        status = self.status_tracker.status
        return f"ServerGoalHandle({status.goal_id.id!r}, {states.status_name(status.status)})"

    # -- transitions -------------------------------------------------------------------------------

    def set_accepted(self, text: str = "") -> None:
        """PENDING -> ACTIVE, or RECALLING -> PREEMPTING (a cancel came first: the user must see it)."""
        self._move(
            {states.PENDING: states.ACTIVE, states.RECALLING: states.PREEMPTING}, text, None, "an active"
        )

    def set_rejected(self, result: Any = None, text: str = "") -> None:
        self._move(
            {states.PENDING: states.REJECTED, states.RECALLING: states.REJECTED}, text, result, "a rejected"
        )

    def set_canceled(self, result: Any = None, text: str = "") -> None:
        """RECALLED if the goal never ran, PREEMPTED if it did."""
        self._move(
            {
                states.PENDING: states.RECALLED,
                states.RECALLING: states.RECALLED,
                states.ACTIVE: states.PREEMPTED,
                states.PREEMPTING: states.PREEMPTED,
            },
            text,
            result,
            "a cancelled",
        )

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        self._move(
            {states.ACTIVE: states.ABORTED, states.PREEMPTING: states.ABORTED}, text, result, "an aborted"
        )

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        self._move(
            {states.ACTIVE: states.SUCCEEDED, states.PREEMPTING: states.SUCCEEDED},
            text,
            result,
            "a succeeded",
        )

    def publish_feedback(self, feedback: Any) -> None:
        bound = self._bound("publish feedback on")
        if bound is not None:
            bound[1].publish_feedback(bound[0].status, feedback)

    def set_cancel_requested(self) -> bool:
        """A cancel reached this goal: PENDING -> RECALLING, ACTIVE -> PREEMPTING.

        True when the user's cancel callback must hear of it (the goal was pending or active).
        """
        if self.goal is None or self.status_tracker is None or self.action_server is None:
            return False
        server = self.action_server
        with server.lock:
            status = self.status_tracker.status
            new = {states.PENDING: states.RECALLING, states.ACTIVE: states.PREEMPTING}.get(status.status)
            if new is None:
                return False
            status.status = new
        server.status_changed()
        return True

    def _move(self, table: dict[int, int], text: str, result: Any, what: str) -> None:
        bound = self._bound("set the status of")
        if bound is None:
            return
        tracker, server = bound
        with server.lock:
            status = tracker.status
            new = table.get(status.status)
            if new is None:
                server.log.error(
                    "action %s, goal %s: cannot move to %s state from %s (allowed from %s)",
                    server.ns,
                    status.goal_id.id,
                    what,
                    states.status_name(status.status),
                    "/".join(states.status_name(s) for s in table),
                )
                return
            status.status = new
            status.text = text
            if new in states.TERMINAL_STATUSES:
                tracker.destruction_time = stamp_of(server.clock)
                server.publish_result(status, result if result else self.get_default_result())
        server.status_changed()

    def _log_empty(self, what: str) -> None:
        server = self.action_server
        log = server.log if server is not None else resolve_log(None, None, __name__)
        log.error("Attempt to %s an uninitialized ServerGoalHandle", what)


def _nop(_handle: ServerGoalHandle) -> None:
    """The default cancel callback: the user handles cancels by polling the goal's status."""


class ActionServer:
    """Serve one action on ``node`` under namespace ``ns``.

    ``goal_cb(handle)`` runs for each new goal (on the goal topic's thread, with :attr:`lock` held,
    as in ROS 1: SimpleActionServer relies on that), ``cancel_cb(handle)`` for each goal a cancel
    reaches while pending or active. Call :meth:`start` when the callbacks are ready (ROS 1 warns
    against ``auto_start``: a goal can arrive before the constructor returns).
    """

    def __init__(
        self,
        node: Any,
        ns: str,
        action_class: Any,
        goal_cb: Callable[[ServerGoalHandle], Any],
        cancel_cb: Callable[[ServerGoalHandle], Any] = _nop,
        auto_start: bool = False,
        clock: Clock | None = None,
        log: Any = None,
    ) -> None:
        self.node = node
        self.types = ActionTypes.of(action_class)
        # ROS 1's attribute names for the action's classes
        self.ActionSpec = action_class
        self.ActionGoal = self.types.action_goal
        self.ActionResult = self.types.action_result
        self.ActionFeedback = self.types.action_feedback
        self.auto_start = auto_start
        self.ns = node.resolve_name(ns)
        self.clock = resolve_clock(node, clock)
        self.log = resolve_log(node, log, __name__)
        self.goal_callback = goal_cb
        self.cancel_callback = cancel_cb
        self.lock = threading.RLock()
        self.started = False
        #: goal id -> tracker, in arrival order (the order of the published status list)
        self.trackers: dict[str, StatusTracker] = {}
        self.last_cancel = Time()
        self.id_generator = GoalIDGenerator(node.name, self.clock.now_pair)
        self._status_class = goal_status_class()
        self._array_class = goal_status_array_class()
        self._dirty = False  # transitions wait for a merged status publication
        self._last_status = 0.0  # time.monotonic() of the last transition-driven publication
        self._wake = threading.Condition(threading.Lock())
        self._stopped = False
        self._status_thread: threading.Thread | None = None
        self._timer: Timer | None = None
        self.status_pub = self.result_pub = self.feedback_pub = None
        self.goal_sub = self.cancel_sub = None
        if auto_start:
            self.log.warn(
                "You've passed in true for auto_start to the python action server, you should always "
                "pass in false to avoid race conditions."
            )
            self.start()

    # -- ROS 1 API ---------------------------------------------------------------------------------

    @property
    def ActionResultType(self) -> type:  # noqa: N802 - ROS 1's attribute name
        return self.types.result

    @property
    def status_list(self) -> StatusList:
        """ROS 1's list of the goals' trackers, in arrival order; editing it edits the server's goals."""
        return StatusList(self)

    @property
    def status_timer(self) -> Timer | None:
        """The timer that publishes the status list ``actionlib_status_frequency`` times a second."""
        return self._timer

    def register_goal_callback(self, cb: Callable[[ServerGoalHandle], Any]) -> None:
        self.goal_callback = cb

    def register_cancel_callback(self, cancel_cb: Callable[[ServerGoalHandle], Any]) -> None:
        self.cancel_callback = cancel_cb

    def start(self) -> None:
        """Advertise the five topics (with ROS 1's parameters) and publish the first status."""
        with self.lock:
            if self.started:
                return
            self._initialize()
            self.started = True
        self._publish_status()

    def stop(self) -> None:
        """Stop serving: unregister the topics and end the status thread and timer."""
        with self.lock:
            if not self.started:
                return
            self.started = False
        with self._wake:
            self._stopped = True
            self._wake.notify()
        if self._timer is not None:
            self._timer.shutdown()
        for endpoint in (self.goal_sub, self.cancel_sub, self.status_pub, self.feedback_pub, self.result_pub):
            if endpoint is not None:
                endpoint.unregister()
        if self._status_thread is not None and self._status_thread is not threading.current_thread():
            self._status_thread.join(2.0)

    def _param(self, key: str, default: Any) -> Any:
        try:
            return self.node.get_param(key, default)
        except Exception as exc:  # an unreachable master must not stop the server
            self.log.warn("action %s: cannot read parameter %s (%s); using %r", self.ns, key, exc, default)
            return default

    def _initialize(self) -> None:
        node, ns = self.node, self.ns
        pub_queue = self._param("actionlib_server_pub_queue_size", 50)
        if not isinstance(pub_queue, int) or pub_queue < 0:
            pub_queue = 50
        sub_queue = self._param("actionlib_server_sub_queue_size", -1)
        sub_queue = sub_queue if isinstance(sub_queue, int) and sub_queue > 0 else None
        self.pub_queue_size, self.sub_queue_size = pub_queue, sub_queue
        self.status_pub = node.publisher(f"{ns}/status", self._array_class, queue_size=pub_queue, latch=True)
        self.result_pub = node.publisher(f"{ns}/result", self.types.action_result, queue_size=pub_queue)
        self.feedback_pub = node.publisher(f"{ns}/feedback", self.types.action_feedback, queue_size=pub_queue)
        self.goal_sub = node.subscriber(
            f"{ns}/goal", self.types.action_goal, self._on_goal, queue_size=sub_queue
        )
        self.cancel_sub = node.subscriber(
            f"{ns}/cancel", type(self._status_class().goal_id), self._on_cancel, queue_size=sub_queue
        )
        if node.has_param(f"{ns}/status_frequency"):
            frequency = self._param(f"{ns}/status_frequency", 5.0)
            self.log.warn(
                "You're using the deprecated status_frequency parameter, please switch to actionlib_status_frequency."
            )
        else:
            found = None
            try:
                found = node.search_param("actionlib_status_frequency")
            except Exception as exc:
                self.log.warn("action %s: cannot search parameter actionlib_status_frequency (%s)", ns, exc)
            frequency = self._param(found, 5.0) if found else 5.0
        timeout = self._param(f"{ns}/status_list_timeout", 5.0)
        try:
            self.status_frequency = float(frequency)
        except (TypeError, ValueError):
            self.log.warn("action %s: status frequency %r is not a number; using 5.0", ns, frequency)
            self.status_frequency = 5.0
        try:
            self.status_list_timeout = Duration.from_sec(float(timeout))
        except (TypeError, ValueError):
            self.log.warn("action %s: %s/status_list_timeout %r is not a number; using 5.0", ns, ns, timeout)
            self.status_list_timeout = Duration.from_sec(5.0)
        self._stopped = False
        self._status_thread = threading.Thread(
            target=self._status_loop, name=f"action-status:{ns}", daemon=True
        )
        self._status_thread.start()
        if self.status_frequency > 0.0:
            self._timer = Timer(
                self.clock, 1.0 / self.status_frequency, self._on_timer, name=f"action-timer:{ns}"
            )
        node.on_shutdown(self._on_shutdown)

    # -- what the goal handles call ----------------------------------------------------------------

    def publish_result(self, status: Any, result: Any) -> None:
        msg = self.types.action_result()
        msg.header.stamp = stamp_of(self.clock)
        msg.status = self._copy_status(status)
        msg.result = result
        if self.result_pub is not None and not self.node.is_shutdown:
            self.result_pub.publish(msg)

    def publish_feedback(self, status: Any, feedback: Any) -> None:
        msg = self.types.action_feedback()
        msg.header.stamp = stamp_of(self.clock)
        msg.status = self._copy_status(status)
        msg.feedback = feedback
        if self.feedback_pub is not None and not self.node.is_shutdown:
            self.feedback_pub.publish(msg)

    def _copy_status(self, status: Any) -> Any:
        copy = self._status_class()
        copy.goal_id = status.goal_id
        copy.status = status.status
        copy.text = status.text
        return copy

    def status_changed(self) -> None:
        """A goal moved: publish the status list now, or, within MERGE_INTERVAL of the last such
        publication, have the status thread send one list for all the transitions meanwhile."""
        with self._wake:
            if self._dirty:
                return  # a merged publication is due and will include this transition
            now = time.monotonic()
            if now - self._last_status < MERGE_INTERVAL:
                self._dirty = True
                self._wake.notify()
                return
            self._last_status = now
        self._publish_status()

    def publish_status(self) -> None:
        """ROS 1's name: publish the status list now, from this thread."""
        self._publish_status()

    def flush_status(self) -> None:
        """Publish now the status list a merged publication is pending for, if any."""
        with self._wake:
            if not self._dirty:
                return
            self._dirty = False
            self._last_status = time.monotonic()
        self._publish_status()

    # -- topic callbacks -----------------------------------------------------------------------------

    def _on_goal(self, action_goal: Any) -> None:
        with self.lock:
            if not self.started:
                return
            goal_id = action_goal.goal_id
            tracker = self.trackers.get(goal_id.id) if goal_id.id else None
            if tracker is not None:
                if tracker.status.status == states.RECALLING and tracker.goal is None:
                    # its cancel came first: recall it now (a result, so the client finishes)
                    tracker.status.status = states.RECALLED
                    tracker.status.text = "This goal was canceled before it arrived at the action server"
                    tracker.destruction_time = stamp_of(self.clock)
                    self.log.info(
                        "action %s: goal %s arrived after its cancel: recalled", self.ns, goal_id.id
                    )
                    self.publish_result(tracker.status, self.types.result())
                    self.status_changed()
                else:
                    self.log.warn(
                        "action %s: goal id %s sent again (it is %s); the repeat is ignored",
                        self.ns,
                        goal_id.id,
                        states.status_name(tracker.status.status),
                    )
                return
            status = self._status_class()
            status.goal_id = goal_id
            status.status = states.PENDING
            if not goal_id.id:  # named and stamped by the server, as in ROS 1
                status.goal_id = self.id_generator.generate_ID()
            elif goal_id.stamp.is_zero():
                status.goal_id.stamp = stamp_of(self.clock)
            tracker = StatusTracker(status, action_goal)
            self.trackers[status.goal_id.id] = tracker
            handle = ServerGoalHandle(tracker, self)
            if not goal_id.stamp.is_zero() and goal_id.stamp <= self.last_cancel:
                handle.set_canceled(
                    None,
                    "This goal handle was canceled by the action server because its timestamp is before "
                    "the timestamp of the last cancel request",
                )
                return
            self.goal_callback(handle)

    def _on_cancel(self, goal_id: Any) -> None:
        with self.lock:
            if not self.started:
                return
            cancel_all = not goal_id.id and goal_id.stamp.is_zero()
            by_stamp = not goal_id.stamp.is_zero()
            if cancel_all or by_stamp:
                targets = [
                    t
                    for t in list(self.trackers.values())
                    if cancel_all
                    or t.status.goal_id.id == goal_id.id
                    or t.status.goal_id.stamp <= goal_id.stamp
                ]
            else:
                one = self.trackers.get(goal_id.id)
                targets = [one] if one is not None else []
            found = False
            for tracker in targets:
                if tracker.status.goal_id.id == goal_id.id:
                    found = True
                if tracker.goal is None:
                    continue  # a remembered cancel: nothing to tell a user yet
                handle = ServerGoalHandle(tracker, self)
                if handle.set_cancel_requested():
                    self.cancel_callback(handle)
            if goal_id.id and not found:
                status = self._status_class()
                status.goal_id = goal_id
                status.status = states.RECALLING
                tracker = StatusTracker(status)
                tracker.destruction_time = stamp_of(self.clock)
                self.trackers[goal_id.id] = tracker
                self.log.info(
                    "action %s: cancel for goal %s, which has not arrived: remembered, it will be recalled if it does",
                    self.ns,
                    goal_id.id,
                )
                self.status_changed()
            if goal_id.stamp > self.last_cancel:
                self.last_cancel = goal_id.stamp

    # -- status publishing -------------------------------------------------------------------------

    def _status_array(self) -> Any:
        """The status list now, dropping terminal goals older than the status list timeout."""
        now = stamp_of(self.clock)
        timeout = self.status_list_timeout
        array = self._array_class()
        with self.lock:
            expired = [
                key
                for key, t in self.trackers.items()
                if not t.destruction_time.is_zero() and t.destruction_time + timeout < now
            ]
            for key in expired:
                del self.trackers[key]
            array.status_list = [self._copy_status(t.status) for t in self.trackers.values()]
        array.header.stamp = now
        return array

    def _publish_status(self) -> None:
        """Build and publish under the server lock: the timer and the status thread both publish, and
        an older list sent after a newer one would make clients think a goal vanished (LOST)."""
        with self.lock:
            if self.status_pub is None or self.node.is_shutdown or not self.started:
                return
            self.status_pub.publish(self._status_array())

    def _on_timer(self, _event: Any) -> None:
        self._publish_status()

    def _status_loop(self) -> None:
        """Send the merged status lists of bursts (wall time: a paused simulation must not hold
        status back)."""
        wake = self._wake
        while True:
            with wake:
                while not self._dirty and not self._stopped:
                    wake.wait()
                if self._stopped:
                    return
                delay = self._last_status + MERGE_INTERVAL - time.monotonic()
                if delay > 0 and wake.wait_for(lambda: self._stopped, delay):
                    return
                self._dirty = False
                self._last_status = time.monotonic()
            self._publish_status()

    def _on_shutdown(self) -> None:
        with self._wake:
            self._stopped = True
            self._wake.notify()
        if self._timer is not None:
            self._timer.shutdown()
