"""``tf2_ros.BufferClient``: lookups answered by a remote tf2 buffer (``rosrun tf2_ros buffer_server``)
over its ``tf2_msgs/LookupTransform`` action, for nodes that should not listen to ``/tf`` themselves."""

from __future__ import annotations

from typing import Any

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from tf2_msgs.msg import LookupTransformAction, LookupTransformGoal, TF2Error
from tf2_ros import BufferInterface

__all__ = ["BufferClient"]

#: the server's error codes -> what the client raises (any other nonzero code: TransformException)
_ERRORS = {
    TF2Error.LOOKUP_ERROR: LookupException,
    TF2Error.CONNECTIVITY_ERROR: ConnectivityException,
    TF2Error.EXTRAPOLATION_ERROR: ExtrapolationException,
    TF2Error.INVALID_ARGUMENT_ERROR: InvalidArgumentException,
    TF2Error.TIMEOUT_ERROR: TimeoutException,
}


class BufferClient(BufferInterface):
    """``BufferClient(ns, check_frequency=None, timeout_padding=rospy.Duration(2.0))``: the buffer
    server's action is ``ns`` (``"tf2_buffer_server"`` for ``rosrun tf2_ros buffer_server``).

    Each lookup is one goal; the answer must come within the lookup's ``timeout`` plus
    ``timeout_padding``, else TimeoutException. ``transform()`` works as on a local Buffer.
    """

    def __init__(
        self, ns: str, check_frequency: Any = None, timeout_padding: Any = rospy.Duration.from_sec(2.0)
    ) -> None:
        BufferInterface.__init__(self)
        self.client = actionlib.SimpleActionClient(ns, LookupTransformAction)
        self.timeout_padding = timeout_padding
        if check_frequency is not None:
            rospy.logwarn("Argument check_frequency is deprecated and should not be used.")

    def wait_for_server(self, timeout: Any = None) -> bool:
        """Whether the buffer server is there, waiting up to ``timeout`` (zero or None: forever)."""
        return self.client.wait_for_server(rospy.Duration() if timeout is None else timeout)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> Any:
        goal = LookupTransformGoal()
        goal.target_frame = target_frame
        goal.source_frame = source_frame
        goal.source_time = time
        goal.timeout = _duration(timeout)
        goal.advanced = False
        return self._process_goal(goal)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        goal = LookupTransformGoal()
        goal.target_frame = target_frame
        goal.source_frame = source_frame
        goal.source_time = source_time
        goal.timeout = _duration(timeout)
        goal.target_time = target_time
        goal.fixed_frame = fixed_frame
        goal.advanced = True
        return self._process_goal(goal)

    def can_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> bool:
        try:
            self.lookup_transform(target_frame, source_frame, time, timeout)
            return True
        except TransformException:
            return False

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> bool:
        try:
            self.lookup_transform_full(
                target_frame, target_time, source_frame, source_time, fixed_frame, timeout
            )
            return True
        except TransformException:
            return False

    def _process_goal(self, goal: Any) -> Any:
        self.client.send_goal(goal)
        if not self.client.wait_for_result(goal.timeout + self.timeout_padding):
            raise TimeoutException(
                "The LookupTransform goal sent to the BufferServer did not come back in the specified time. "
                "Something is likely wrong with the server"
            )
        if self.client.get_state() != GoalStatus.SUCCEEDED:
            raise TimeoutException(
                "The LookupTransform goal sent to the BufferServer did not come back with SUCCEEDED status. "
                "Something is likely wrong with the server."
            )
        return _process_result(self.client.get_result())


def _duration(timeout: Any) -> Any:
    if timeout is None:
        return rospy.Duration()
    return timeout if isinstance(timeout, rospy.Duration) else rospy.Duration.from_sec(float(timeout))


def _process_result(result: Any) -> Any:
    if not result:
        raise TransformException(
            "The BufferServer returned None for result!  Something is likely wrong with the server."
        )
    if not result.error:
        raise TransformException(
            "The BufferServer returned None for result.error!  Something is likely wrong with the server."
        )
    code = result.error.error
    if code != TF2Error.NO_ERROR:
        raise _ERRORS.get(code, TransformException)(result.error.error_string)
    return result.transform
