"""The client's goal state machine and the goal id formats, without a node."""

from __future__ import annotations

import re

import pytest
from actionlib_fakes import ListLog

from actionlib_msgs.msg import GoalStatus
from actionlib_tutorials.msg import FibonacciActionFeedback, FibonacciActionGoal, FibonacciActionResult
from ninjemys.actionlib import states
from ninjemys.actionlib.client import ClientGoalHandle, CommStateMachine
from ninjemys.actionlib.goal_id import GoalIDGenerator, client_goal_id
from ninjemys.actionlib.states import CommState, comm_transitions

S = states


def machine(log: ListLog | None = None) -> tuple[CommStateMachine, list[int], list]:
    seen: list[int] = []
    sent: list = []
    goal = FibonacciActionGoal()
    goal.goal_id.id = "g1"
    csm = CommStateMachine(
        goal,
        lambda gh: seen.append(gh.get_comm_state()),
        None,
        sent.append,
        sent.append,
        log or ListLog(),
    )
    return csm, seen, sent


def status(code: int, goal_id: str = "g1") -> GoalStatus:
    s = GoalStatus(status=code)
    s.goal_id.id = goal_id
    return s


def test_status_codes_are_the_wire_values() -> None:
    for name, value in S.STATUS_NAMES.items():
        assert getattr(GoalStatus, value) == name


@pytest.mark.parametrize(
    ("state", "status", "path"),
    [
        (CommState.WAITING_FOR_GOAL_ACK, S.PENDING, (CommState.PENDING,)),
        (CommState.WAITING_FOR_GOAL_ACK, S.SUCCEEDED, (CommState.ACTIVE, CommState.WAITING_FOR_RESULT)),
        (
            CommState.WAITING_FOR_GOAL_ACK,
            S.PREEMPTED,
            (CommState.ACTIVE, CommState.PREEMPTING, CommState.WAITING_FOR_RESULT),
        ),
        (CommState.PENDING, S.RECALLED, (CommState.RECALLING, CommState.WAITING_FOR_RESULT)),
        (CommState.ACTIVE, S.ACTIVE, ()),
        (CommState.ACTIVE, S.PENDING, None),
        (CommState.WAITING_FOR_CANCEL_ACK, S.SUCCEEDED, (CommState.PREEMPTING, CommState.WAITING_FOR_RESULT)),
        (CommState.PREEMPTING, S.RECALLED, None),
        (CommState.DONE, S.SUCCEEDED, ()),
    ],
)
def test_transition_table(state: int, status: int, path: tuple[int, ...] | None) -> None:
    assert comm_transitions(state, status) == path


def test_every_state_knows_every_status_a_server_sends() -> None:
    for state in range(CommState.DONE + 1):
        for code in range(S.RECALLED + 1):
            comm_transitions(state, code)  # no KeyError


def test_status_skipping_states_runs_each_transition() -> None:
    csm, seen, _ = machine()
    csm.update_status(status(S.SUCCEEDED))
    assert seen == [CommState.ACTIVE, CommState.WAITING_FOR_RESULT]
    result = FibonacciActionResult()
    result.status = status(S.SUCCEEDED)
    result.result.sequence = [0, 1]
    csm.update_result(result)
    assert seen[-1] == CommState.DONE
    handle = ClientGoalHandle(csm)
    assert handle.get_result().sequence == [0, 1]
    assert handle.get_terminal_state() == S.SUCCEEDED


def test_result_before_any_status_goes_straight_to_done() -> None:
    csm, seen, _ = machine()
    result = FibonacciActionResult()
    result.status = status(S.ABORTED)
    csm.update_result(result)
    assert seen == [CommState.ACTIVE, CommState.WAITING_FOR_RESULT, CommState.DONE]
    assert ClientGoalHandle(csm).get_goal_status() == S.ABORTED


def test_goal_missing_from_status_after_ack_is_lost_with_one_line() -> None:
    log = ListLog()
    csm, seen, _ = machine(log)
    csm.update_status(None)  # not acknowledged yet: nothing happens
    assert seen == []
    csm.update_status(status(S.ACTIVE))
    csm.update_status(None)
    assert seen == [CommState.ACTIVE, CommState.DONE]
    assert ClientGoalHandle(csm).get_goal_status() == S.LOST
    assert len(log.at("warn")) == 1 and "g1" in log.at("warn")[0] and "LOST" in log.at("warn")[0]


def result_of(code: int) -> FibonacciActionResult:
    result = FibonacciActionResult()
    result.status = status(code)
    return result


def test_cancel_before_any_list_names_the_goal_is_not_lost_on_an_older_list() -> None:
    """The smach flake: the goal runs on the server, the user cancels before a status list naming it
    came, and a list the server sent before it had the goal arrives late. ROS 1 marks it LOST (then
    drops the PREEMPTED result as 'already DONE'); it must end PREEMPTED."""
    log = ListLog()
    csm, seen, _ = machine(log)
    ClientGoalHandle(csm).cancel()
    csm.update_status(None)  # the older list
    assert seen == [CommState.WAITING_FOR_CANCEL_ACK]
    csm.update_status(status(S.PREEMPTING))
    csm.update_status(status(S.PREEMPTED))
    csm.update_result(result_of(S.PREEMPTED))
    assert seen[-1] == CommState.DONE
    assert ClientGoalHandle(csm).get_terminal_state() == S.PREEMPTED
    assert log.at("warn") == [] and log.at("error") == []


def test_feedback_before_any_list_does_not_make_an_older_list_lose_the_goal() -> None:
    """Feedback (another topic) can overtake the status list that would name the goal."""
    csm, seen, _ = machine()
    feedback = FibonacciActionFeedback()
    feedback.status = status(S.ACTIVE)
    csm.update_feedback(feedback)
    assert seen == [CommState.ACTIVE]
    csm.update_status(None)
    ClientGoalHandle(csm).cancel()
    csm.update_status(None)
    assert seen == [CommState.ACTIVE, CommState.WAITING_FOR_CANCEL_ACK]
    csm.update_result(result_of(S.PREEMPTED))
    assert ClientGoalHandle(csm).get_terminal_state() == S.PREEMPTED


LISTED = {"active": S.ACTIVE, "preempting": S.PREEMPTING, "preempted": S.PREEMPTED}


@pytest.mark.parametrize(
    "events",
    [
        # the result before any list shows the cancel
        ["active", "cancel", "result"],
        # the result before the list that says PREEMPTING, then lists without the goal
        ["active", "cancel", "result", "missing", "preempted"],
        # the list says PREEMPTED, the goal leaves the list, then the result comes
        ["active", "cancel", "preempting", "preempted", "missing", "result"],
        # cancel before the ack, the result overtakes every list
        ["cancel", "result", "missing"],
        # cancel before the ack, an older list, then the lists and the result
        ["cancel", "missing", "preempting", "result"],
    ],
)
def test_cancelled_goal_ends_preempted_whatever_the_order(events: list[str]) -> None:
    log = ListLog()
    csm, _, _ = machine(log)
    for event in events:
        if event == "cancel":
            ClientGoalHandle(csm).cancel()
        elif event == "result":
            csm.update_result(result_of(S.PREEMPTED))
        elif event == "missing":
            csm.update_status(None)
        else:
            csm.update_status(status(LISTED[event]))
    assert csm.state == CommState.DONE
    assert ClientGoalHandle(csm).get_terminal_state() == S.PREEMPTED
    assert log.at("warn") == [] and log.at("error") == []


def test_invalid_and_unknown_statuses_are_one_error_line_each_and_change_nothing() -> None:
    log = ListLog()
    csm, seen, _ = machine(log)
    csm.update_status(status(S.ACTIVE))
    csm.update_status(status(S.PENDING))
    csm.update_status(status(42))
    assert seen == [CommState.ACTIVE]
    errors = log.at("error")
    assert len(errors) == 2
    assert "invalid goal status transition from ACTIVE to PENDING" in errors[0]
    assert "unknown status 42" in errors[1]


def test_cancel_sends_the_goal_id_and_waits_for_ack() -> None:
    csm, seen, sent = machine()
    ClientGoalHandle(csm).cancel()
    assert sent[-1].id == "g1" and sent[-1].stamp.is_zero()
    assert seen == [CommState.WAITING_FOR_CANCEL_ACK]
    csm.update_status(status(S.RECALLED))
    assert seen[1:] == [CommState.RECALLING, CommState.WAITING_FOR_RESULT]


def test_to_string_names() -> None:
    assert CommState.to_string(CommState.WAITING_FOR_RESULT) == "WAITING_FOR_RESULT"
    assert S.SimpleGoalState.to_string(2) == "DONE"
    assert S.TerminalState.to_string(S.LOST) == "LOST"
    assert CommState.to_string(99) == "NO_SUCH_STATE_99"


def test_goal_id_formats() -> None:
    now = lambda: (1700000000, 5)  # noqa: E731
    server = GoalIDGenerator("/srv", now).generate_ID()
    assert re.fullmatch(r"/srv-\d+-1700000000\.5", server.id)
    assert (server.stamp.secs, server.stamp.nsecs) == (1700000000, 5)
    client = client_goal_id("/cli", now)
    assert re.fullmatch(r"/cli-\d+-1700000000\.000", client.id)
    assert client_goal_id("/cli", now).id != client.id  # a process-wide counter
