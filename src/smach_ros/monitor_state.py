"""MonitorState: watch a topic while ``cond_cb(ud, msg)`` stays True.

The first False gives 'invalid'; ``max_checks`` Trues in a row give 'valid' (-1: watch forever);
a preempt gives 'preempted'. Classic use: a Concurrence child that ends the moment a condition breaks.
"""

from __future__ import annotations

import threading
from typing import Any

import rospy
import smach

__all__ = ["MonitorState"]


class MonitorState(smach.State):
    """``MonitorState(topic, MsgType, cond_cb, max_checks=-1)``."""

    def __init__(
        self,
        topic: str,
        msg_type: Any,
        cond_cb: Any,
        max_checks: int = -1,
        input_keys: list[str] | tuple[str, ...] = (),
        output_keys: list[str] | tuple[str, ...] = (),
    ) -> None:
        super().__init__(
            outcomes=["valid", "invalid", "preempted"], input_keys=input_keys, output_keys=output_keys
        )
        self._topic = topic
        self._msg_type = msg_type
        self._cond_cb = cond_cb
        self._max_checks = max_checks
        self._n_checks = 0
        self._trigger_event = threading.Event()
        self._sub: Any = None

    def execute(self, ud: Any) -> str | None:
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        self._n_checks = 0
        self._trigger_event.clear()
        self._sub = rospy.Subscriber(self._topic, self._msg_type, self._cb, callback_args=ud)
        try:
            self._trigger_event.wait()
        finally:
            self._sub.unregister()
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        if 0 < self._max_checks <= self._n_checks:
            return "valid"
        return "invalid"

    def _cb(self, msg: Any, ud: Any) -> None:
        if self._trigger_event.is_set():
            return
        try:
            if self._cond_cb(ud, msg):
                self._n_checks += 1
            else:
                self._trigger_event.set()
        except Exception as exc:
            rospy.logerr(f"Error thrown while executing condition callback {self._cond_cb}: {exc}")
            self._trigger_event.set()
        if 0 < self._max_checks <= self._n_checks:
            self._trigger_event.set()

    def request_preempt(self) -> None:
        super().request_preempt()
        self._trigger_event.set()
