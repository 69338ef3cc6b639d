"""smach_ros states refuse bad construction with one clear smach error, before touching ROS."""

from __future__ import annotations

import pytest

import smach
import smach_ros
from actionlib.msg import TwoIntsAction, TwoIntsGoal
from std_srvs.srv import SetBool


@pytest.fixture(autouse=True)
def quiet() -> None:
    smach.set_loggers(*(lambda m: None,) * 4)


def test_simple_action_state_names_bad_slots_and_goal() -> None:
    with pytest.raises(
        smach.InvalidStateError,
        match=r"Goal slots specified are not valid slots. Available slots: \['a', 'b'\]; specified slots: \['a', 'c'\]",
    ):
        smach_ros.SimpleActionState("add", TwoIntsAction, goal_slots=["a", "c"])
    with pytest.raises(smach.InvalidStateError, match="Result slots specified are not valid slots"):
        smach_ros.SimpleActionState("add", TwoIntsAction, result_slots=["product"])
    with pytest.raises(smach.InvalidStateError, match="IS a function object"):
        smach_ros.SimpleActionState("add", TwoIntsAction, goal=lambda: TwoIntsGoal())


def test_service_state_refuses_a_callback_that_is_not_callable() -> None:
    with pytest.raises(smach.InvalidStateError, match="IS NOT a function object"):
        smach_ros.ServiceState("set", SetBool, request_cb="not a function")


def test_callback_interfaces_register_outcomes_and_keys() -> None:
    @smach.cb_interface(outcomes=["rejected"], input_keys=["limit"], output_keys=["ok"])
    def response_cb(ud, response):
        return None

    state = smach_ros.ServiceState(
        "set", SetBool, response_cb=response_cb, request_slots=["data"], response_key="resp"
    )
    assert set(state.get_registered_outcomes()) == {"succeeded", "aborted", "preempted", "rejected"}
    assert set(state.get_registered_input_keys()) == {"limit", "data"}
    assert set(state.get_registered_output_keys()) == {"ok", "resp"}
    monitor = smach_ros.MonitorState("flag", SetBool._request_class, lambda ud, m: True, input_keys=["x"])
    assert set(monitor.get_registered_outcomes()) == {"valid", "invalid", "preempted"}
    cond = smach_ros.ConditionState(lambda ud: True)
    assert set(cond.get_registered_outcomes()) == {"true", "false", "preempted"}
