"""``set_preempt_handler``: preempt a running container when the node shuts down (Ctrl-C)."""

from __future__ import annotations

import threading
from typing import Any

import rospy


def set_preempt_handler(sc: Any) -> None:
    """On shutdown, preempt ``sc`` and wait (logging each second) until it stops running."""

    def handler() -> None:
        sc.request_preempt()
        stopped = threading.Event()
        while sc.is_running() and not stopped.wait(1.0):
            rospy.loginfo(
                "Received shutdown request... sent preempt... waiting for state machine to terminate."
            )

    rospy.on_shutdown(handler)
