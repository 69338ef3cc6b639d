"""SimpleActionServer: one goal at a time, on top of :class:`~ninjemys.actionlib.server.ActionServer`.

A new goal preempts the current one: it becomes the *next* goal and the current goal's
``is_preempt_requested()`` turns true; the user (or the execute loop) takes it with
``accept_new_goal()``. A goal stamped earlier than the current or next goal is cancelled at once.
With an ``execute_cb``, a thread runs it for each accepted goal; a callback that returns without
setting a terminal state gets its goal aborted, as in ROS 1, and so does one that raises (with the
traceback logged). Unlike ROS 1's loop, which sleeps 0.1 s between goals when a goal arrived while
the previous one was executing, ours checks for a waiting goal before it sleeps.
"""

from __future__ import annotations

import threading
import traceback
from collections.abc import Callable

from ninjemys.actionlib import states
from ninjemys.actionlib.server import ActionServer, ServerGoalHandle
from ninjemys.node.clock import Clock

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

_SUPERSEDED = "This goal was canceled because another goal was received by the simple action server"


class SimpleActionServer:
    def __init__(
        self,
        node: Any,
        name: str,
        action_class: Any,
        execute_cb: Callable[[Any], Any] | None = None,
        auto_start: bool = False,
        clock: Clock | None = None,
        log: Any = None,
    ) -> None:
        self.new_goal = False
        self.preempt_request = False
        self.new_goal_preempt_request = False
        self.execute_callback = execute_cb
        self.goal_callback: Callable[[], Any] | None = None
        self.preempt_callback: Callable[[], Any] | None = None
        self.need_to_terminate = False
        self.lock = threading.RLock()
        self.execute_condition = threading.Condition(self.lock)
        self.current_goal = ServerGoalHandle()
        self.next_goal = ServerGoalHandle()
        self.action_server = ActionServer(
            node,
            name,
            action_class,
            self._on_goal,
            self._on_preempt,
            auto_start=False,
            clock=clock,
            log=log,
        )
        self.log = self.action_server.log
        self.node = node
        self.execute_thread: threading.Thread | None = None
        if execute_cb is not None:
            self.execute_thread = threading.Thread(
                target=self._execute_loop, name=f"action-execute:{self.action_server.ns}", daemon=True
            )
            self.execute_thread.start()
            node.on_shutdown(self._terminate)
        if auto_start:
            self.action_server.log.warn(
                "You've passed in true for auto_start to the python action server, you should always "
                "pass in false to avoid race conditions."
            )
            self.start()

    def start(self) -> None:
        self.action_server.start()

    def stop(self) -> None:
        """Stop serving and end the execute thread (ROS 1 does this in ``__del__``)."""
        self._terminate()
        self.action_server.stop()
        thread = self.execute_thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(5.0)

    def _terminate(self) -> None:
        with self.execute_condition:
            self.need_to_terminate = True
            self.execute_condition.notify_all()

    # -- the ROS 1 API -----------------------------------------------------------------------------

    def accept_new_goal(self) -> Any:
        """Make the next goal the current one (ACTIVE) and return its FooGoal."""
        with self.action_server.lock, self.lock:
            if not self.new_goal or self.next_goal.get_goal() is None:
                self.log.error("Attempting to accept the next goal when a new goal is not available")
                return None
            if (
                self.is_active()
                and self.current_goal.get_goal() is not None
                and self.current_goal != self.next_goal
            ):
                self.current_goal.set_canceled(None, _SUPERSEDED)
            self.current_goal = self.next_goal
            self.new_goal = False
            self.preempt_request = self.new_goal_preempt_request
            self.new_goal_preempt_request = False
            self.current_goal.set_accepted("This goal has been accepted by the simple action server")
            return self.current_goal.get_goal()

    def is_new_goal_available(self) -> bool:
        return self.new_goal

    def is_preempt_requested(self) -> bool:
        return self.preempt_request

    def is_active(self) -> bool:
        if self.current_goal.get_goal() is None:
            return False
        return self.current_goal.get_goal_status().status in (states.ACTIVE, states.PREEMPTING)

    def get_default_result(self) -> Any:
        return self.action_server.types.result()

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            self.current_goal.set_succeeded(result if result else self.get_default_result(), text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            self.current_goal.set_aborted(result if result else self.get_default_result(), text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            self.current_goal.set_canceled(result if result else self.get_default_result(), text)

    def publish_feedback(self, feedback: Any) -> None:
        self.current_goal.publish_feedback(feedback)

    def register_goal_callback(self, cb: Callable[[], Any]) -> None:
        if self.execute_callback is not None:
            self.log.warn(
                "Cannot call SimpleActionServer.register_goal_callback() because an executeCallback exists. "
                "Not going to register it."
            )
        else:
            self.goal_callback = cb

    def register_preempt_callback(self, cb: Callable[[], Any]) -> None:
        self.preempt_callback = cb

    # -- callbacks of the action server ------------------------------------------------------------

    def _on_goal(self, goal: ServerGoalHandle) -> None:
        with self.execute_condition:
            stamp = goal.get_goal_id().stamp
            current, following = self.current_goal, self.next_goal
            newest = (current.get_goal() is None or stamp >= current.get_goal_id().stamp) and (
                following.get_goal() is None or stamp >= following.get_goal_id().stamp
            )
            if not newest:
                goal.set_canceled(None, _SUPERSEDED)
                return
            if following.get_goal() is not None and (current.get_goal() is None or following != current):
                following.set_canceled(None, _SUPERSEDED)
            self.next_goal = goal
            self.new_goal = True
            self.new_goal_preempt_request = False
            if self.is_active():
                self.preempt_request = True
                if self.preempt_callback is not None:
                    self.preempt_callback()
            if self.goal_callback is not None:
                self.goal_callback()
            self.execute_condition.notify()

    def _on_preempt(self, preempt: ServerGoalHandle) -> None:
        with self.lock:
            if preempt == self.current_goal:
                self.preempt_request = True
                if self.preempt_callback is not None:
                    self.preempt_callback()
            elif preempt == self.next_goal:
                self.new_goal_preempt_request = True

    # -- the execute thread --------------------------------------------------------------------------

    def _execute_loop(self) -> None:
        callback = self.execute_callback
        assert callback is not None
        while True:
            with self.execute_condition:
                while not self.new_goal and not self.need_to_terminate and not self.node.is_shutdown:
                    self.execute_condition.wait(0.5)  # the node's shutdown hook notifies; 0.5 s is a backstop
                if self.need_to_terminate or self.node.is_shutdown:
                    return
            if self.is_active():
                self.log.error("Should never reach this code with an active goal")
                return
            # outside the condition: accept_new_goal takes the server's lock first, as the goal
            # callback (holding it) takes ours, so the two orders never cross
            goal = self.accept_new_goal()
            if goal is None:
                continue
            try:
                callback(goal)
                if self.is_active():
                    self.log.warn(
                        "Your executeCallback did not set the goal to a terminal status.  This is a bug in your "
                        "ActionServer implementation. Fix your code!  For now, the ActionServer will set this "
                        "goal to aborted"
                    )
                    self.set_aborted(None, "No terminal state was set.")
            except Exception as exc:
                self.log.error("Exception in your execute callback: %s\n%s", exc, traceback.format_exc())
                self.set_aborted(None, f"Exception in execute callback: {exc}")
