"""ServiceState: one service call as a state (succeeded / aborted / preempted).

The request is built from ``request``, then ``request_key`` (a whole request from userdata), then
``request_slots`` (fields from userdata keys of the same names), then ``request_cb(ud, request)``; the
response goes back through ``response_cb(ud, response)`` (which may choose the outcome),
``response_key`` and ``response_slots``.
"""

from __future__ import annotations

import traceback
from typing import Any

import rospy
import smach
from smach_ros._callbacks import interface_of

__all__ = ["ServiceState"]


class ServiceState(smach.State):
    """``ServiceState(service_name, ServiceType, request=..., response_cb=..., ...)``."""

    def __init__(
        self,
        service_name: str,
        service_spec: Any,
        request: Any = None,
        request_cb: Any = None,
        request_cb_args: list[Any] | tuple[Any, ...] = (),
        request_cb_kwargs: dict[str, Any] | None = None,
        request_key: str | None = None,
        request_slots: list[str] | tuple[str, ...] = (),
        response_cb: Any = None,
        response_cb_args: list[Any] | tuple[Any, ...] = (),
        response_cb_kwargs: dict[str, Any] | None = None,
        response_key: str | None = None,
        response_slots: list[str] | tuple[str, ...] = (),
        input_keys: list[str] | tuple[str, ...] = (),
        output_keys: list[str] | tuple[str, ...] = (),
        outcomes: list[str] | tuple[str, ...] = (),
    ) -> None:
        super().__init__(outcomes=["succeeded", "aborted", "preempted"])
        self._service_name = service_name
        self._service_spec = service_spec
        self._proxy: Any = None
        self._request = service_spec._request_class() if request is None else request
        self._request_cb = request_cb
        self._request_cb_args = list(request_cb_args)
        self._request_cb_kwargs = dict(request_cb_kwargs or {})
        self._request_cb_keys = interface_of(self, request_cb, input_keys, output_keys)
        self._request_key = request_key
        if request_key is not None:
            self.register_input_keys([request_key])
        self._request_slots = list(request_slots)
        self.register_input_keys(self._request_slots)
        self._response_cb = response_cb
        self._response_cb_args = list(response_cb_args)
        self._response_cb_kwargs = dict(response_cb_kwargs or {})
        self._response_cb_keys = interface_of(self, response_cb, input_keys, output_keys, outcomes=True)
        self.register_input_keys(input_keys)
        self.register_output_keys(output_keys)
        self.register_outcomes(outcomes)
        self._response_key = response_key
        if response_key is not None:
            self.register_output_keys([response_key])
        self._response_slots = list(response_slots)
        self.register_output_keys(self._response_slots)
        self._response: Any = None

    def _connect(self) -> str | None:
        """Wait for the service (in 1 s slices, so a preempt or shutdown gets through); None once connected."""
        while self._proxy is None:
            if self.preempt_requested():
                rospy.loginfo(f"Preempting while waiting for service '{self._service_name}'.")
                self.service_preempt()
                return "preempted"
            if rospy.is_shutdown():
                rospy.loginfo(f"Shutting down while waiting for service '{self._service_name}'.")
                return "aborted"
            try:
                rospy.wait_for_service(self._service_name, 1.0)
            except rospy.ROSInterruptException:
                rospy.logwarn(f"Terminated while waiting for service '{self._service_name}'.")
                return "aborted"
            except rospy.ROSException:
                rospy.logwarn(f"Still waiting for service '{self._service_name}'...")
                continue
            self._proxy = rospy.ServiceProxy(self._service_name, self._service_spec)
            rospy.logdebug(f"Connected to service '{self._service_name}'")
        return None

    def execute(self, ud: Any) -> str | None:
        if self.preempt_requested():
            rospy.loginfo(f"Preempting {self._service_name} before sending request.")
            self.service_preempt()
            return "preempted"
        early = self._connect()
        if early is not None:
            return early
        if self._request_key is not None:
            if self._request_key not in ud:
                rospy.logerr(
                    f"Requested request key '{self._request_key}' not in userdata struture. Available keys are: {list(ud.keys())}"
                )
                return "aborted"
            self._request = ud[self._request_key]
        for key in self._request_slots:
            if key not in ud:
                rospy.logerr(
                    f"Requested request slot key '{key}' is not in userdata strcture. Available keys are: {list(ud.keys())}"
                )
                return "aborted"
            setattr(self._request, key, ud[key])
        if self._request_cb is not None:
            try:
                update = self._request_cb(
                    smach.Remapper(ud, *self._request_cb_keys, {}),
                    self._request,
                    *self._request_cb_args,
                    **self._request_cb_kwargs,
                )
            except Exception:
                rospy.logerr("Could not execute request callback: " + traceback.format_exc())
                return "aborted"
            if update is not None:
                self._request = update
        if self._request is None:
            rospy.logerr(f"Attempting to call service {self._service_name} with no request")
            return "aborted"
        try:
            rospy.logdebug(f"Calling service {self._service_name} with request:\n{self._request}")
            self._response = self._proxy(self._request)
        except rospy.ServiceException as ex:
            rospy.logerr(f"Exception when calling service '{self._service_name}': {ex}")
            return "aborted"
        cb_outcome = None
        if self._response_cb is not None:
            try:
                cb_outcome = self._response_cb(
                    smach.Remapper(ud, *self._response_cb_keys, {}),
                    self._response,
                    *self._response_cb_args,
                    **self._response_cb_kwargs,
                )
            except Exception:
                rospy.logerr("Could not execute response callback: " + traceback.format_exc())
                return "aborted"
            if cb_outcome is not None and cb_outcome not in self.get_registered_outcomes():
                rospy.logerr(
                    f"Result callback for service {self._service_name}, {self._response_cb} was not registered "
                    f"with the response_cb_outcomes argument. The response callback returned '{cb_outcome}' but "
                    f"the only registered outcomes are: {self.get_registered_outcomes()}"
                )
                return "aborted"
        if self._response_key is not None:
            ud[self._response_key] = self._response
        for key in self._response_slots:
            ud[key] = getattr(self._response, key)
        return cb_outcome if cb_outcome is not None else "succeeded"
