"""The action client: goals out on ``<ns>/goal`` and ``cancel``; status, feedback and results back.

Each goal sent gets a :class:`CommStateMachine` that turns what the server reports (status lists,
results) into the client's CommState, through :func:`ninjemys.actionlib.states.comm_transitions`.
The user holds a :class:`ClientGoalHandle`; the client keeps only a weak reference to each machine,
as ROS 1 does, so a goal whose handle the user drops stops being tracked.

``wait_for_server`` is true only when one server (the node sending status) is connected on all five
topics in the right direction: it subscribes to our goal and cancel topics and we are connected to
its status, result and feedback. Only then can a goal sent next not lose its result (actionlib#181).
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Callable

from ninjemys.actionlib import states
from ninjemys.actionlib.common import (
    ActionTypes,
    goal_id_class,
    goal_status_array_class,
    goal_status_class,
    resolve_clock,
    resolve_log,
    seconds,
    stamp_of,
)
from ninjemys.actionlib.goal_id import client_goal_id
from ninjemys.actionlib.states import CommState
from ninjemys.errors import NinjemysError
from ninjemys.master.client import MasterClient
from ninjemys.node.clock import Clock
from ninjemys.rostime import Time

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

#: seconds between two checks of the connections while a server is half connected (the node layer
#: has no event for "a connection completed"; the status message that starts the check is an event)
CONNECT_POLL = 0.005


class CommStateMachine:
    """One goal as the client sees it; every method is safe from any thread (``mutex``)."""

    def __init__(
        self,
        action_goal: Any,
        transition_cb: Callable[[ClientGoalHandle], Any] | None,
        feedback_cb: Callable[[ClientGoalHandle, Any], Any] | None,
        send_goal_fn: Callable[[Any], Any],
        send_cancel_fn: Callable[[Any], Any],
        log: Any,
    ) -> None:
        self.action_goal = action_goal
        self.transition_cb = transition_cb
        self.feedback_cb = feedback_cb
        self.send_goal_fn = send_goal_fn
        self.send_cancel_fn = send_cancel_fn
        self.log = log
        self.state = CommState.WAITING_FOR_GOAL_ACK
        self.mutex = threading.RLock()
        self.latest_goal_status = goal_status_class()(status=states.PENDING)
        self.latest_result: Any = None
        # whether a status list has named this goal: only then does a list without it mean the server
        # forgot it (see update_status)
        self._listed = False

    @property
    def goal_id(self) -> str:
        return self.action_goal.goal_id.id

    def __eq__(self, other: object) -> bool:
        return isinstance(other, CommStateMachine) and self.goal_id == other.goal_id

    def __hash__(self) -> int:
        return hash(self.goal_id)

    def set_state(self, state: int) -> None:
        """Set the comm state without telling the user (ROS 1's name; :meth:`transition_to` tells)."""
        with self.mutex:
            self.state = state

    def transition_to(self, state: int) -> None:
        self.state = state
        if self.transition_cb is not None:
            self.transition_cb(ClientGoalHandle(self))

    def update_status(self, status: Any | None) -> None:
        """This goal's entry in a status list from the server (None: the list does not name it).

        A list without the goal marks it LOST only once an earlier list named it. ROS 1 also marks it
        LOST when the user cancelled before any list named it (WAITING_FOR_CANCEL_ACK straight from
        WAITING_FOR_GOAL_ACK) or when feedback moved it to ACTIVE first: then a list the server sent
        before the goal reached it, delivered late (a loaded machine, an unbounded queue), loses a
        goal the server is running, and its PREEMPTED result comes to a goal already DONE. Status
        lists come in order on one connection, so "named once, now missing" is the server's word;
        "never named yet" is only a list older than the goal.
        """
        with self.mutex:
            if self.state == CommState.DONE:
                return
            if status is None:
                # the server named this goal once and has forgotten it: it is lost
                if self._listed and self.state not in (
                    CommState.WAITING_FOR_GOAL_ACK,
                    CommState.WAITING_FOR_RESULT,
                ):
                    self.log.warn(
                        "goal %s: the action server no longer lists it (state %s): marking it LOST",
                        self.goal_id,
                        CommState.to_string(self.state),
                    )
                    self.latest_goal_status.status = states.LOST
                    self.transition_to(CommState.DONE)
                return
            self._listed = True
            self._apply_status(status)

    def _apply_status(self, status: Any) -> None:
        """Move through the states ``status`` implies (the caller holds ``mutex``)."""
        self.latest_goal_status = status
        try:
            path = states.comm_transitions(self.state, status.status)
        except KeyError:
            self.log.error("goal %s: the action server sent unknown status %r", self.goal_id, status.status)
            return
        if path is None:
            self.log.error(
                "goal %s: invalid goal status transition from %s to %s",
                self.goal_id,
                CommState.to_string(self.state),
                states.status_name(status.status),
            )
            return
        for state in path:
            self.transition_to(state)

    def update_result(self, action_result: Any) -> None:
        with self.mutex:
            self.latest_goal_status = action_result.status
            self.latest_result = action_result
            if self.state == CommState.DONE:
                self.log.error("goal %s: got a result when already DONE", self.goal_id)
                return
            self._apply_status(action_result.status)
            if self.state != CommState.DONE:
                self.transition_to(CommState.DONE)

    def update_feedback(self, action_feedback: Any) -> None:
        with self.mutex:
            if self.state in (CommState.WAITING_FOR_GOAL_ACK, CommState.PENDING):
                # feedback can overtake the status list that says the goal is active (another
                # topic): its own status says so too, so the user sees active before feedback
                self._apply_status(action_feedback.status)
            if self.state == CommState.DONE:
                return
        if self.feedback_cb is not None:
            self.feedback_cb(ClientGoalHandle(self), action_feedback.feedback)


class ClientGoalHandle:
    """The user's handle on a goal it sent: state, status, result, cancel."""

    def __init__(self, comm_state_machine: CommStateMachine | None) -> None:
        self.comm_state_machine = comm_state_machine

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ClientGoalHandle):
            return False
        return self.comm_state_machine == other.comm_state_machine

    def __ne__(self, other: object) -> bool:
        return not self == other

    def __hash__(self) -> int:
        return hash(self.comm_state_machine)

    def __repr__(self) -> str:
        csm = self.comm_state_machine
        if csm is None:
            return "ClientGoalHandle(inactive)"
        return f"ClientGoalHandle({csm.goal_id!r}, {CommState.to_string(csm.state)})"

    def cancel(self) -> None:
        csm = self._csm("cancel")
        if csm is None:
            return
        with csm.mutex:
            cancel = goal_id_class()()
            cancel.id = csm.goal_id
            cancel.stamp = Time()
            csm.send_cancel_fn(cancel)
            csm.transition_to(CommState.WAITING_FOR_CANCEL_ACK)

    def resend(self) -> None:
        """Send the goal again (same id), e.g. after the server restarted."""
        csm = self._csm("resend")
        if csm is not None:
            csm.send_goal_fn(csm.action_goal)

    def get_comm_state(self) -> int:
        csm = self._csm("get_comm_state")
        return CommState.LOST if csm is None else csm.state

    def get_goal_status(self) -> int:
        csm = self._csm("get_goal_status")
        return states.PENDING if csm is None else csm.latest_goal_status.status

    def get_goal_status_text(self) -> str:
        csm = self._csm("get_goal_status_text")
        if csm is None:
            return "ERROR: Trying to get_goal_status_text on an inactive ClientGoalHandle."
        return csm.latest_goal_status.text

    def get_result(self) -> Any:
        csm = self._csm("get_result")
        if csm is None or csm.latest_result is None:
            return None
        return csm.latest_result.result

    def get_terminal_state(self) -> int:
        csm = self._csm("get_terminal_state")
        if csm is None:
            return states.LOST
        with csm.mutex:
            if csm.state != CommState.DONE:
                csm.log.warn(
                    "Asking for the terminal state when we're in [%s]", CommState.to_string(csm.state)
                )
            status = csm.latest_goal_status.status
            if status in states.TERMINAL_STATUSES:
                return status
            csm.log.error("Asking for a terminal state, but the goal status is %d", status)
            return states.LOST

    def _csm(self, what: str) -> CommStateMachine | None:
        if self.comm_state_machine is None:
            resolve_log(None, None, __name__).error("Trying to %s on an inactive ClientGoalHandle.", what)
        return self.comm_state_machine


class ActionClient:
    """Send goals of one action to the server under ``ns`` and track them."""

    def __init__(
        self,
        node: Any,
        ns: str,
        action_class: Any,
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
        self.ns = node.resolve_name(ns)
        self.clock = resolve_clock(node, clock)
        self.log = resolve_log(node, log, __name__)
        self._goals: weakref.WeakValueDictionary[str, CommStateMachine] = weakref.WeakValueDictionary()
        self._goals_lock = threading.Lock()
        self._status_class = goal_status_array_class()
        self._server_id: str | None = None  # caller id of the node whose status we heard last
        self._confirmed: str | None = None  # the server whose own bus info listed our subscriptions
        self._status_seen = threading.Condition(threading.Lock())
        self.last_status_msg: Any = None
        # Goals and cancels are never dropped unless the user asks for a bounded queue: ROS 1's
        # default of 10 would drop goals of a loop that sends more than 10 at once
        pub_queue = self._param("actionlib_client_pub_queue_size", None)
        if pub_queue is not None and not (isinstance(pub_queue, int) and pub_queue > 0):
            pub_queue = 10  # ROS 1 turns a negative size into its default
        sub_queue = self._param("actionlib_client_sub_queue_size", -1)
        sub_queue = sub_queue if isinstance(sub_queue, int) and sub_queue > 0 else None
        self.pub_queue_size, self.sub_queue_size = pub_queue, sub_queue
        ns = self.ns
        self.pub_goal = node.publisher(f"{ns}/goal", self.types.action_goal, queue_size=pub_queue)
        self.pub_cancel = node.publisher(f"{ns}/cancel", goal_id_class(), queue_size=pub_queue)
        # raw: the status sender's caller id (from its connection header) names the server
        self.status_sub = node.subscriber(
            f"{ns}/status", self._status_class, self._on_status, raw=True, queue_size=sub_queue
        )
        self.result_sub = node.subscriber(
            f"{ns}/result", self.types.action_result, self._on_result, queue_size=sub_queue
        )
        self.feedback_sub = node.subscriber(
            f"{ns}/feedback", self.types.action_feedback, self._on_feedback, queue_size=sub_queue
        )

    def _param(self, key: str, default: Any) -> Any:
        try:
            return self.node.get_param(key, default)
        except Exception as exc:
            self.log.warn(
                "action client %s: cannot read parameter %s (%s); using %r", self.ns, key, exc, default
            )
            return default

    def stop(self) -> None:
        for endpoint in (self.pub_goal, self.pub_cancel, self.status_sub, self.result_sub, self.feedback_sub):
            endpoint.unregister()

    # -- goals ---------------------------------------------------------------------------------------

    def send_goal(
        self,
        goal: Any,
        transition_cb: Callable[[ClientGoalHandle], Any] | None = None,
        feedback_cb: Callable[[ClientGoalHandle, Any], Any] | None = None,
    ) -> ClientGoalHandle:
        """Send ``goal`` (a FooGoal); the callbacks run on the status/result/feedback threads."""
        handle = self.prepare_goal(goal, transition_cb, feedback_cb)
        handle.resend()
        return handle

    def prepare_goal(
        self,
        goal: Any,
        transition_cb: Callable[[ClientGoalHandle], Any] | None = None,
        feedback_cb: Callable[[ClientGoalHandle, Any], Any] | None = None,
    ) -> ClientGoalHandle:
        """Make and track a goal without sending it (``handle.resend()`` sends it).

        SimpleActionClient stores the handle before the goal leaves, so a result that comes back
        at once cannot reach a transition callback that does not know its handle yet (ROS 1's
        "transition callback on a goal handle that we're not tracking", actionlib#126).
        """
        action_goal = self.types.action_goal()
        action_goal.goal_id = client_goal_id(self.node.name, self.clock.now_pair)
        action_goal.header.stamp = stamp_of(self.clock)
        action_goal.goal = goal
        csm = CommStateMachine(
            action_goal, transition_cb, feedback_cb, self.pub_goal.publish, self.pub_cancel.publish, self.log
        )
        with self._goals_lock:
            self._goals[csm.goal_id] = csm
        return ClientGoalHandle(csm)

    def cancel_all_goals(self) -> None:
        self.pub_cancel.publish(goal_id_class()())

    def cancel_goals_at_and_before_time(self, time: Any) -> None:
        cancel = goal_id_class()()
        cancel.stamp = time
        self.pub_cancel.publish(cancel)

    # -- server discovery ----------------------------------------------------------------------------

    def missing(self) -> str | None:
        """What is still missing before a goal is safe to send, or None when nothing is."""
        server = self._server_id
        if server is None:
            publishers = self.status_sub.publisher_ids()
            if publishers:
                return f"connected to {self.ns}/status of {', '.join(sorted(publishers))} but no status received yet"
            return f"no action server publishes {self.ns}/status (is the action name right?)"
        lacking = [
            f"{self.ns}/{topic} (its {what})"
            for topic, what, ids in (
                ("goal", "subscriber", self.pub_goal.subscriber_ids),
                ("cancel", "subscriber", self.pub_cancel.subscriber_ids),
                ("result", "publisher", self.result_sub.publisher_ids),
                ("feedback", "publisher", self.feedback_sub.publisher_ids),
            )
            if server not in ids()
        ]
        if lacking:
            self._confirmed = None  # a lost connection is confirmed again when it is back
            return f"action server {server} is not connected yet on {', '.join(lacking)}"
        if self._confirmed != server:
            if not self._server_lists_us(server):
                return (
                    f"action server {server} has not added our {self.ns}/result and feedback connections yet"
                )
            self._confirmed = server
        return None

    def _server_lists_us(self, server: str) -> bool:
        """Whether the server's own getBusInfo lists our result and feedback subscriptions. rospy answers
        a subscriber's handshake before it adds the connection to the publisher, so a result published
        in between (a fast server, a loaded machine) is lost although both ends look connected here.
        A server we cannot ask (no slave API, a timeout) is trusted on the handshake."""
        wanted = {f"{self.ns}/result", f"{self.ns}/feedback"}
        me = self.node.name
        try:
            client = MasterClient(self.node.master.lookup_node(server), caller_id=me, timeout=2.0)
            try:
                rows = client.call("getBusInfo")
            finally:
                client.close()
        except (NinjemysError, OSError, ValueError) as exc:
            self.log.debug("action client %s: cannot ask %s for its connections (%s)", self.ns, server, exc)
            return True
        listed = {
            row[4]
            for row in rows
            if isinstance(row, (list, tuple)) and len(row) > 4 and row[1] == me and row[2] == "o"
        }
        return wanted <= listed

    def wait_for_server(self, timeout: Any = 0.0) -> bool:
        """True once a server is connected on all five topics; False after ``timeout`` seconds (0: forever).

        A False return logs one line saying what is missing (no status publisher at all usually
        means a wrong action name, actionlib#35).
        """
        limit = seconds(timeout)
        clock = self.clock
        deadline = clock.now() + limit if limit > 0 else None
        what = self.missing()
        while what is not None:
            if self.node.is_shutdown:
                return False
            now = clock.now()
            if deadline is not None and now >= deadline:
                self.log.warn("wait_for_server(%s): gave up after %.1f s: %s", self.ns, limit, what)
                return False
            step = CONNECT_POLL if self._server_id is not None else 0.1
            if deadline is not None:
                step = min(step, deadline - now)
            with self._status_seen:  # a first status message ends the wait early
                self._status_seen.wait(step)
            what = self.missing()
        return True

    wait_for_action_server_to_start = wait_for_server

    # -- topic callbacks ---------------------------------------------------------------------------

    def _live(self) -> list[CommStateMachine]:
        with self._goals_lock:
            return list(self._goals.values())

    def _on_status(self, raw: Any) -> None:
        try:
            msg = self._status_class.deserialize_from(raw.data)
        except Exception as exc:
            self.log.warn("action client %s: undecodable status message (%s); ignored", self.ns, exc)
            return
        msg._connection_header = raw.connection_header
        self.last_status_msg = msg
        sender = raw.connection_header.get("callerid")
        if sender != self._server_id:
            with self._status_seen:
                self._server_id = sender
                self._status_seen.notify_all()
        by_id = {s.goal_id.id: s for s in msg.status_list}
        for csm in self._live():
            csm.update_status(by_id.get(csm.goal_id))

    def _on_result(self, msg: Any) -> None:
        with self._goals_lock:
            csm = self._goals.get(msg.status.goal_id.id)
        if csm is not None:  # results of other clients' goals come by too: not ours, not an error
            csm.update_result(msg)

    def _on_feedback(self, msg: Any) -> None:
        with self._goals_lock:
            csm = self._goals.get(msg.status.goal_id.id)
        if csm is not None:
            csm.update_feedback(msg)
