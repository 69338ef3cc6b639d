"""ConditionState: evaluate ``cond_cb(ud)`` at ``poll_rate`` until it is True ('true'), ``max_checks``
are used up or ``timeout`` passes ('false'), or a preempt arrives ('preempted').

The condition is user code with no event to wait on, so this state polls by design, as smach's does;
the wait between checks is interrupted at once by a preempt.
"""

from __future__ import annotations

import threading
import time
import traceback
from typing import Any

import rospy
import smach

__all__ = ["ConditionState"]


def _seconds(d: Any) -> float | None:
    if d is None:
        return None
    return d.to_sec() if hasattr(d, "to_sec") else float(d)


class ConditionState(smach.State):
    """``ConditionState(cond_cb, input_keys=[], poll_rate=0.05, timeout=None, max_checks=1)``."""

    def __init__(
        self,
        cond_cb: Any,
        input_keys: list[str] | tuple[str, ...] = (),
        poll_rate: Any = 0.05,
        timeout: Any = None,
        max_checks: int = 1,
    ) -> None:
        super().__init__(outcomes=["true", "false", "preempted"], input_keys=input_keys)
        self._cond_cb = cond_cb
        if smach.has_smach_interface(cond_cb):
            self.register_input_keys(cond_cb.get_registered_input_keys())
            self.register_output_keys(cond_cb.get_registered_output_keys())
        self._poll_rate = _seconds(poll_rate) or 0.0
        self._timeout = _seconds(timeout)
        self._max_checks = max_checks
        self._wakeup = threading.Event()

    def execute(self, ud: Any) -> str | None:
        start = time.monotonic()
        checks = 0
        self._wakeup.clear()
        while self._max_checks == -1 or checks <= self._max_checks:
            if self._timeout and time.monotonic() - start > self._timeout:
                break
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            try:
                if self._cond_cb(ud):
                    return "true"
            except Exception as exc:
                raise smach.InvalidUserCodeError(
                    f"Error thrown while executing condition callback {self._cond_cb}: "
                    + traceback.format_exc()
                ) from exc
            checks += 1
            if rospy.is_shutdown():
                break
            self._wakeup.wait(self._poll_rate)
        return "false"

    def request_preempt(self) -> None:
        super().request_preempt()
        self._wakeup.set()
