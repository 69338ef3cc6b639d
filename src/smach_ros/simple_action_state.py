"""SimpleActionState: an actionlib goal as a state (succeeded / aborted / preempted).

The goal is built from ``goal``, then ``goal_key`` (a whole goal from userdata), then ``goal_slots``
(goal fields copied from userdata keys of the same names), then ``goal_cb(ud, goal)``. The result
goes back through ``result_cb(ud, status, result)`` (which may choose the outcome), ``result_key`` and
``result_slots``. The server is waited for in the background from construction on, so building a
machine never blocks on a server that is late.
"""

from __future__ import annotations

import copy
import threading
import time
import traceback
from typing import Any

import rospy
import smach
from actionlib import SimpleActionClient
from actionlib_msgs.msg import GoalStatus
from smach_ros._callbacks import interface_of

__all__ = ["SimpleActionState"]

_STATUS_NAMES = ("PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED", "REJECTED", "LOST")


def _seconds(d: Any) -> float | None:
    if d is None:
        return None
    return d.to_sec() if hasattr(d, "to_sec") else float(d)


class SimpleActionState(smach.State):
    """``SimpleActionState(action_name, ActionSpec, goal=..., result_cb=..., ...)``."""

    WAITING_FOR_SERVER = 0
    INACTIVE = 1
    ACTIVE = 2
    PREEMPTING = 3
    COMPLETED = 4

    def __init__(
        self,
        action_name: str,
        action_spec: Any,
        goal: Any = None,
        goal_key: str | None = None,
        goal_slots: list[str] | tuple[str, ...] = (),
        goal_cb: Any = None,
        goal_cb_args: list[Any] | tuple[Any, ...] = (),
        goal_cb_kwargs: dict[str, Any] | None = None,
        result_key: str | None = None,
        result_slots: list[str] | tuple[str, ...] = (),
        result_cb: Any = None,
        result_cb_args: list[Any] | tuple[Any, ...] = (),
        result_cb_kwargs: dict[str, Any] | None = None,
        input_keys: list[str] | tuple[str, ...] = (),
        output_keys: list[str] | tuple[str, ...] = (),
        outcomes: list[str] | tuple[str, ...] = (),
        exec_timeout: Any = None,
        preempt_timeout: Any = 60.0,
        server_wait_timeout: Any = 60.0,
    ) -> None:
        super().__init__(outcomes=["succeeded", "aborted", "preempted"])
        self._action_name = action_name
        self._action_spec = action_spec
        if goal is not None and callable(goal):
            raise smach.InvalidStateError("Goal object given to SimpleActionState that IS a function object")
        goal_fields = list(action_spec().action_goal.goal.__slots__)
        if not all(s in goal_fields for s in goal_slots):
            raise smach.InvalidStateError(
                f"Goal slots specified are not valid slots. Available slots: {goal_fields}; specified slots: {list(goal_slots)}"
            )
        result_fields = list(action_spec().action_result.result.__slots__)
        if not all(s in result_fields for s in result_slots):
            raise smach.InvalidStateError(
                f"Result slots specified are not valid slots. Available slots: {result_fields}; specified slots: {list(result_slots)}"
            )
        self._goal = copy.copy(action_spec().action_goal.goal) if goal is None else goal
        self._goal_key = goal_key
        if goal_key is not None:
            self.register_input_keys([goal_key])
        self._goal_slots = list(goal_slots)
        self.register_input_keys(self._goal_slots)
        self._goal_cb = goal_cb
        self._goal_cb_args = list(goal_cb_args)
        self._goal_cb_kwargs = dict(goal_cb_kwargs or {})
        self._goal_cb_keys = interface_of(self, goal_cb, input_keys, output_keys)
        self._result_cb = result_cb
        self._result_cb_args = list(result_cb_args)
        self._result_cb_kwargs = dict(result_cb_kwargs or {})
        self._result_cb_keys = interface_of(self, result_cb, input_keys, output_keys, outcomes=True)
        self._result_key = result_key
        if result_key is not None:
            self.register_output_keys([result_key])
        self._result_slots = list(result_slots)
        self.register_output_keys(self._result_slots)
        self.register_input_keys(input_keys)
        self.register_output_keys(output_keys)
        self.register_outcomes(outcomes)
        self._exec_timeout = _seconds(exec_timeout)
        self._preempt_timeout = _seconds(preempt_timeout)
        self._server_wait_timeout = _seconds(server_wait_timeout) or 0.0
        self._goal_status = 0
        self._goal_result: Any = None
        self._done = False
        self._cond = threading.Condition()
        rospy.on_shutdown(self._wake)
        self._status = SimpleActionState.WAITING_FOR_SERVER
        self._action_client = SimpleActionClient(action_name, action_spec)
        self._wait_thread = threading.Thread(
            name=f"{action_name}/wait_for_server", target=self._wait_for_server, daemon=True
        )
        self._wait_thread.start()

    def _wait_for_server(self) -> None:
        try:
            if self._action_client.wait_for_server(self._server_wait_timeout):
                self._status = SimpleActionState.INACTIVE
        except Exception:
            if not rospy.is_shutdown():
                rospy.logerr(f"Failed to wait for action server '{self._action_name}'")

    def request_preempt(self) -> None:
        rospy.loginfo(f"Preempt requested on action '{self._action_name}'")
        super().request_preempt()
        if self._status == SimpleActionState.ACTIVE:
            rospy.loginfo(f"Preempt on action '{self._action_name}' cancelling goal: \n{self._goal}")
            self._action_client.cancel_goal()
        self._wake()

    def execute(self, ud: Any) -> str | None:
        if self._status == SimpleActionState.WAITING_FOR_SERVER:
            rospy.logwarn(f"Still waiting for action server '{self._action_name}' to start... is it running?")
            if self._wait_thread.is_alive():
                self._wait_thread.join()
            else:
                self._wait_for_server()
            if not self.preempt_requested() and self._status != SimpleActionState.WAITING_FOR_SERVER:
                rospy.loginfo(f"Connected to action server '{self._action_name}'.")
        if self.preempt_requested():
            rospy.loginfo(f"Preempting {self._action_name} before sending goal.")
            self.service_preempt()
            return "preempted"
        if self._status == SimpleActionState.WAITING_FOR_SERVER:
            rospy.logfatal(f"Action server for {self._action_name} is not running.")
            return "aborted"
        self._status = SimpleActionState.INACTIVE
        if self._goal_key is not None:
            self._goal = ud[self._goal_key]
        for key in self._goal_slots:
            setattr(self._goal, key, ud[key])
        if self._goal_cb is not None:
            try:
                update = self._goal_cb(
                    smach.Remapper(ud, *self._goal_cb_keys, {}),
                    self._goal,
                    *self._goal_cb_args,
                    **self._goal_cb_kwargs,
                )
            except Exception:
                rospy.logerr("Could not execute goal callback: " + traceback.format_exc())
                return "aborted"
            if update is not None:
                self._goal = update
        if self._goal is None:
            rospy.logerr(
                f"Attempting to activate action {self._action_name} with no goal or goal callback set. Did you "
                "construct the SimpleActionState properly?"
            )
            return "aborted"
        self._done = False
        self._goal_result = None
        self._status = SimpleActionState.ACTIVE
        self._action_client.send_goal(
            self._goal, self._goal_done_cb, self._goal_active_cb, self._goal_feedback_cb
        )
        if self.preempt_requested():  # a preempt that arrived while the goal was being sent
            self._action_client.cancel_goal()
        self._wait_for_result()
        return self._finish(ud)

    def _wait_for_result(self) -> None:
        """Block until the goal ends; cancel it when ``exec_timeout`` runs out, and give up waiting
        ``preempt_timeout`` after a preempt the server does not answer. Wakes on events only (the
        result, a preempt request, node shutdown), never by polling."""
        exec_deadline = time.monotonic() + self._exec_timeout if self._exec_timeout else None
        preempt_deadline = None
        with self._cond:
            while not self._done and not rospy.is_shutdown():
                now = time.monotonic()
                if exec_deadline is not None and now >= exec_deadline:
                    rospy.logwarn(
                        f"Action {self._action_name} timed out after {int(self._exec_timeout or 0)} seconds."
                    )
                    self._action_client.cancel_goal()
                    exec_deadline = None
                if self.preempt_requested() and self._preempt_timeout and preempt_deadline is None:
                    preempt_deadline = now + self._preempt_timeout
                if preempt_deadline is not None and now >= preempt_deadline:
                    rospy.logwarn(
                        f"Action {self._action_name} did not answer the preempt within {self._preempt_timeout} seconds."
                    )
                    self._goal_status = GoalStatus.PREEMPTED
                    self._status = SimpleActionState.INACTIVE
                    return
                deadlines = [d for d in (exec_deadline, preempt_deadline) if d is not None]
                self._cond.wait(min(deadlines) - now if deadlines else None)

    def _wake(self) -> None:
        with self._cond:
            self._cond.notify_all()

    def _finish(self, ud: Any) -> str:
        cb_outcome = None
        if self._result_cb is not None:
            try:
                cb_outcome = self._result_cb(
                    smach.Remapper(ud, *self._result_cb_keys, {}),
                    self._goal_status,
                    self._goal_result,
                    *self._result_cb_args,
                    **self._result_cb_kwargs,
                )
            except Exception:
                rospy.logerr("Could not execute result callback: " + traceback.format_exc())
                return "aborted"
            if cb_outcome is not None and cb_outcome not in self.get_registered_outcomes():
                rospy.logerr(
                    f"Result callback for action {self._action_name}, {self._result_cb} was not registered with "
                    f"the result_cb_outcomes argument. The result callback returned '{cb_outcome}' but the only "
                    f"registered outcomes are: {self.get_registered_outcomes()}"
                )
                return "aborted"
        if self._result_key is not None:
            ud[self._result_key] = self._goal_result
        if self._goal_result is not None:
            for key in self._result_slots:
                ud[key] = getattr(self._goal_result, key)
        if self._status != SimpleActionState.INACTIVE:
            rospy.logwarn("Action state terminated without going inactive first.")
            outcome = "aborted"
        elif self._goal_status == GoalStatus.SUCCEEDED:
            outcome = "succeeded"
        elif self._goal_status == GoalStatus.PREEMPTED and self.preempt_requested():
            outcome = "preempted"
            self.service_preempt()
        else:
            outcome = "aborted"
        self._status = SimpleActionState.INACTIVE
        return cb_outcome if cb_outcome is not None else outcome

    def _goal_active_cb(self) -> None:
        rospy.logdebug(f"Action {self._action_name} has gone active.")

    def _goal_feedback_cb(self, feedback: Any) -> None:
        rospy.logdebug(f"Action {self._action_name} sent feedback.")

    def _goal_done_cb(self, result_state: int, result: Any) -> None:
        name = (
            _STATUS_NAMES[result_state]
            if 0 <= result_state < len(_STATUS_NAMES)
            else f"UNKNOWN ({result_state})"
        )
        rospy.logdebug(f"Action {self._action_name} terminated with result {name}.")
        self._goal_status = result_state
        self._goal_result = result
        with self._cond:
            self._status = SimpleActionState.INACTIVE
            self._done = True
            self._cond.notify_all()
