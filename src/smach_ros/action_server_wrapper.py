"""ActionServerWrapper: serve a smach container as an actionlib action.

Each goal runs the container: the goal lands in userdata (``goal_key``, optionally its fields one by
one), feedback in ``feedback_key`` is published on every transition, and the container's outcome
picks the result status (succeeded / preempted / aborted outcome sets). A client's cancel preempts
the container.
"""

from __future__ import annotations

import copy
import traceback
from typing import Any

import rospy
import smach
from actionlib import SimpleActionServer

__all__ = ["ActionServerWrapper"]


class ActionServerWrapper:
    """``ActionServerWrapper(server_name, ActionSpec, wrapped_container, succeeded_outcomes=[...], ...)``."""

    def __init__(
        self,
        server_name: str,
        action_spec: Any,
        wrapped_container: smach.Container,
        succeeded_outcomes: list[str] | tuple[str, ...] = (),
        aborted_outcomes: list[str] | tuple[str, ...] = (),
        preempted_outcomes: list[str] | tuple[str, ...] = (),
        goal_key: str = "action_goal",
        feedback_key: str = "action_feedback",
        result_key: str = "action_result",
        goal_slots_map: dict[str, str] | None = None,
        feedback_slots_map: dict[str, str] | None = None,
        result_slots_map: dict[str, str] | None = None,
        expand_goal_slots: bool = False,
        pack_result_slots: bool = False,
    ) -> None:
        self.wrapped_container = wrapped_container
        wrapped_container.register_transition_cb(self.transition_cb)
        wrapped_container.register_termination_cb(self.termination_cb)
        self.userdata = smach.UserData()
        self._goal_key = goal_key
        self._feedback_key = feedback_key
        self._result_key = result_key
        self._goal_slots_map = dict(goal_slots_map or {})
        self._feedback_slots_map = dict(feedback_slots_map or {})
        self._result_slots_map = dict(result_slots_map or {})
        self._expand_goal_slots = expand_goal_slots
        self._pack_result_slots = pack_result_slots
        spec = action_spec()
        self.userdata[goal_key] = copy.copy(spec.action_goal.goal)
        self.userdata[result_key] = copy.copy(spec.action_result.result)
        self.userdata[feedback_key] = copy.copy(spec.action_feedback.feedback)
        self._server_name = server_name
        self._action_spec = action_spec
        self._action_server = SimpleActionServer(
            server_name, action_spec, execute_cb=self.execute_cb, auto_start=False
        )
        self._succeeded_outcomes = set(succeeded_outcomes)
        self._aborted_outcomes = set(aborted_outcomes)
        self._preempted_outcomes = set(preempted_outcomes)
        sets = (self._succeeded_outcomes, self._aborted_outcomes, self._preempted_outcomes)
        if len(set().union(*sets)) != sum(len(s) for s in sets):
            rospy.logerr(
                "Succeeded, aborted, and preempted outcome lists were not mutually disjoint... expect undefined behavior."
            )

    def run_server(self) -> None:
        """Start serving goals (returns at once)."""
        self._action_server.register_preempt_callback(self.preempt_cb)
        self._action_server.start()
        rospy.loginfo(f"Started SMACH action server wrapper, advertising as '{self._server_name}'")

    def transition_cb(self, userdata: Any, active_states: Any) -> None:
        rospy.logdebug("Publishing action feedback.")
        self.publish_feedback(userdata)

    def termination_cb(self, userdata: Any, terminal_states: Any, container_outcome: Any) -> None:
        rospy.logdebug(
            f"Wrapped state machine has terminated with final state: {terminal_states} and container outcome: {container_outcome}"
        )

    def publish_feedback(self, userdata: Any) -> None:
        """Publish ``userdata[feedback_key]`` (and mapped feedback fields) as the goal's feedback."""
        if self._feedback_key not in userdata:
            return
        feedback = userdata[self._feedback_key]
        for from_key, to_key in self._feedback_slots_map.items():
            if to_key in userdata:
                setattr(feedback, from_key, userdata[to_key])
        self._action_server.publish_feedback(feedback)

    def execute_cb(self, goal: Any) -> None:
        """Run the container for one goal and report its outcome as the goal's status."""
        rospy.logdebug("Starting wrapped SMACH container")
        if self._expand_goal_slots:
            for slot in goal.__slots__:
                self.userdata[slot] = getattr(goal, slot)
        self.userdata[self._goal_key] = goal
        for from_key, to_key in self._goal_slots_map.items():
            self.userdata[to_key] = getattr(goal, from_key)
        container = self.wrapped_container
        try:
            outcome = container.execute(
                smach.Remapper(
                    self.userdata,
                    container.get_registered_input_keys(),
                    container.get_registered_output_keys(),
                    {},
                )
            )
        except smach.InvalidUserCodeError:
            rospy.logerr("Exception thrown while executing wrapped container.")
            self._action_server.set_aborted()
            return
        except Exception:
            rospy.logerr("Exception thrown:while executing wrapped container: " + traceback.format_exc())
            self._action_server.set_aborted()
            return
        result = self.userdata[self._result_key]
        for from_key, to_key in self._result_slots_map.items():
            setattr(result, from_key, self.userdata[to_key])
        if self._pack_result_slots:
            for slot in result.__slots__:
                if slot in self.userdata:
                    setattr(result, slot, self.userdata[slot])
        if outcome in self._succeeded_outcomes:
            rospy.loginfo("SUCCEEDED")
            self._action_server.set_succeeded(result)
        elif outcome in self._preempted_outcomes:
            rospy.loginfo("PREEMPTED")
            self._action_server.set_preempted(result)
        else:
            rospy.loginfo("ABORTED")
            self._action_server.set_aborted(result)

    def preempt_cb(self) -> None:
        rospy.loginfo("Preempt on state machine requested!")
        self.wrapped_container.request_preempt()
