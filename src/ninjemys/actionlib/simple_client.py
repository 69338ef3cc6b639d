"""SimpleActionClient: one goal at a time, seen as PENDING -> ACTIVE -> DONE.

Built on :class:`~ninjemys.actionlib.client.ActionClient`. ``send_goal`` forgets the previous goal
(its callbacks stop) and tracks the new one; ``done_cb(state, result)``, ``active_cb()`` and
``feedback_cb(feedback)`` run on the client's topic threads. The handle of the new goal is stored
before the goal is published, so its result can never race past the bookkeeping (ROS 1 can log
"Got a transition callback on a goal handle that we're not tracking" and lose the DONE, #126).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from ninjemys.actionlib import states
from ninjemys.actionlib.client import ActionClient, ClientGoalHandle
from ninjemys.actionlib.common import seconds
from ninjemys.actionlib.states import CommState, SimpleGoalState
from ninjemys.node.clock import Clock

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any


class SimpleActionClient:
    def __init__(
        self, node: Any, ns: str, action_class: Any, clock: Clock | None = None, log: Any = None
    ) -> None:
        self.action_client = ActionClient(node, ns, action_class, clock=clock, log=log)
        self.node = node
        self.log = self.action_client.log
        self.simple_state = SimpleGoalState.DONE
        self.gh: ClientGoalHandle | None = None
        self.done_cb: Callable[[int, Any], Any] | None = None
        self.active_cb: Callable[[], Any] | None = None
        self.feedback_cb: Callable[[Any], Any] | None = None
        self._lock = threading.RLock()
        self.done_condition = threading.Condition(self._lock)

    def wait_for_server(self, timeout: Any = 0.0) -> bool:
        return self.action_client.wait_for_server(timeout)

    def send_goal(
        self,
        goal: Any,
        done_cb: Callable[[int, Any], Any] | None = None,
        active_cb: Callable[[], Any] | None = None,
        feedback_cb: Callable[[Any], Any] | None = None,
    ) -> None:
        with self._lock:
            self.stop_tracking_goal()
            self.done_cb, self.active_cb, self.feedback_cb = done_cb, active_cb, feedback_cb
            self.simple_state = SimpleGoalState.PENDING
            self.gh = self.action_client.prepare_goal(goal, self._handle_transition, self._handle_feedback)
            handle = self.gh
        handle.resend()

    def send_goal_and_wait(self, goal: Any, execute_timeout: Any = 0.0, preempt_timeout: Any = 0.0) -> int:
        """Send, wait up to ``execute_timeout`` (0: forever), then cancel and wait ``preempt_timeout``."""
        self.send_goal(goal)
        if not self.wait_for_result(execute_timeout):
            self.log.debug("Canceling goal")
            self.cancel_goal()
            if self.wait_for_result(preempt_timeout):
                self.log.debug(
                    "Preempt finished within specified preempt_timeout [%.2f]", seconds(preempt_timeout)
                )
            else:
                self.log.debug(
                    "Preempt didn't finish specified preempt_timeout [%.2f]", seconds(preempt_timeout)
                )
        return self.get_state()

    def wait_for_result(self, timeout: Any = 0.0) -> bool:
        """True when the goal is DONE within ``timeout`` seconds of ROS time (0: wait forever)."""
        if self.gh is None:
            self.log.error("Called wait_for_result when no goal exists")
            return False
        limit = seconds(timeout)
        clock = self.action_client.clock
        deadline = clock.now() + limit if limit > 0 else None
        with self.done_condition:
            while self.simple_state != SimpleGoalState.DONE and not self.node.is_shutdown:
                step = 0.1  # re-checks shutdown and ROS time (which may be simulated)
                if deadline is not None:
                    left = deadline - clock.now()
                    if left <= 0:
                        break
                    step = min(step, left)
                self.done_condition.wait(step)
            return self.simple_state == SimpleGoalState.DONE

    def get_result(self) -> Any:
        if self.gh is None:
            self.log.error("Called get_result when no goal is running")
            return None
        return self.gh.get_result()

    def get_state(self) -> int:
        """The goal's GoalStatus; RECALLING reads as PENDING and PREEMPTING as ACTIVE, as in ROS 1."""
        if self.gh is None:
            return states.LOST
        status = self.gh.get_goal_status()
        if status == states.RECALLING:
            return states.PENDING
        if status == states.PREEMPTING:
            return states.ACTIVE
        return status

    def get_goal_status_text(self) -> str:
        if self.gh is None:
            self.log.error("Called get_goal_status_text when no goal is running")
            return "ERROR: Called get_goal_status_text when no goal is running"
        return self.gh.get_goal_status_text()

    def cancel_all_goals(self) -> None:
        self.action_client.cancel_all_goals()

    def cancel_goals_at_and_before_time(self, time: Any) -> None:
        self.action_client.cancel_goals_at_and_before_time(time)

    def cancel_goal(self) -> None:
        if self.gh is not None:
            self.gh.cancel()

    def stop_tracking_goal(self) -> None:
        self.gh = None

    def get_simple_state(self) -> int:
        return self.simple_state

    # -- callbacks of the goal -----------------------------------------------------------------------

    def _handle_transition(self, gh: ClientGoalHandle) -> None:
        with self._lock:
            if gh != self.gh:
                return  # a goal this client stopped tracking (send_goal replaced it): silently over
            comm = gh.get_comm_state()
            simple = self.simple_state
            call: Callable[[], Any] | None = None
            if comm in (CommState.ACTIVE, CommState.PREEMPTING):
                if simple == SimpleGoalState.PENDING:
                    self.simple_state = SimpleGoalState.ACTIVE
                    call = self.active_cb
                elif simple == SimpleGoalState.DONE:
                    self._log_odd(comm)
            elif comm == CommState.RECALLING:
                if simple != SimpleGoalState.PENDING:
                    self._log_odd(comm)
            elif comm == CommState.DONE:
                if simple == SimpleGoalState.DONE:
                    self.log.error("SimpleActionClient received DONE twice")
                    return
                done_cb = self.done_cb
                status, result = gh.get_goal_status(), gh.get_result()
                if done_cb is not None:
                    done_cb(status, result)
                if self.gh == gh:  # a done_cb that sent the next goal keeps that goal's PENDING
                    self.simple_state = SimpleGoalState.DONE
                self.done_condition.notify_all()
                return
        if call is not None:
            call()

    def _log_odd(self, comm: int) -> None:
        self.log.error(
            "Received comm state %s when in simple state %s with SimpleActionClient in NS %s",
            CommState.to_string(comm),
            SimpleGoalState.to_string(self.simple_state),
            self.action_client.ns,
        )

    def _handle_feedback(self, gh: ClientGoalHandle, feedback: Any) -> None:
        if self.gh is None or gh != self.gh:
            return
        callback = self.feedback_cb
        if callback is not None:
            callback(feedback)
