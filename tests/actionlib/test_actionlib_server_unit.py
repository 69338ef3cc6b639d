"""The server's goal state machine, cancel rules and status list, driven message by message."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from actionlib_fakes import FakeNode, ListLog

from actionlib_msgs.msg import GoalID
from actionlib_tutorials.msg import FibonacciAction, FibonacciActionGoal, FibonacciFeedback, FibonacciResult
from ninjemys.actionlib import states as S
from ninjemys.actionlib.server import ActionServer, ServerGoalHandle
from ninjemys.node.clock import FakeClock
from ninjemys.rostime import Time


class Harness:
    def __init__(self, params: dict[str, Any] | None = None, accept: bool = False) -> None:
        self.node = FakeNode("/srv", params)
        self.clock = FakeClock(100.0)
        self.log = ListLog()
        self.goals: list[ServerGoalHandle] = []
        self.cancels: list[ServerGoalHandle] = []
        self.accept = accept
        self.server = ActionServer(
            self.node, "fib", FibonacciAction, self._goal, self.cancels.append, clock=self.clock, log=self.log
        )
        self.server.start()

    def _goal(self, handle: ServerGoalHandle) -> None:
        self.goals.append(handle)
        if self.accept:
            handle.set_accepted()

    def goal(self, goal_id: str, stamp: float = 0.0, order: int = 1) -> None:
        msg = FibonacciActionGoal()
        msg.goal_id.id = goal_id
        msg.goal_id.stamp = Time.from_sec(stamp)
        msg.goal.order = order
        self.node.subs["/fib/goal"].deliver(msg)

    def cancel(self, goal_id: str = "", stamp: float = 0.0) -> None:
        self.node.subs["/fib/cancel"].deliver(GoalID(id=goal_id, stamp=Time.from_sec(stamp)))

    def statuses(self) -> dict[str, int]:
        array = self.server._status_array()
        return {s.goal_id.id: s.status for s in array.status_list}

    def results(self) -> list[Any]:
        return self.node.pubs["/fib/result"].sent


@pytest.fixture
def h() -> Iterator[Harness]:
    harness = Harness()
    yield harness
    harness.server.stop()


def test_five_topics_with_ros1_types_and_latched_status(h: Harness) -> None:
    pubs, subs = h.node.pubs, h.node.subs
    assert set(pubs) == {"/fib/status", "/fib/result", "/fib/feedback"}
    assert set(subs) == {"/fib/goal", "/fib/cancel"}
    assert pubs["/fib/status"].latch
    assert pubs["/fib/status"].msg_class._type == "actionlib_msgs/GoalStatusArray"
    assert subs["/fib/cancel"].msg_class._type == "actionlib_msgs/GoalID"
    assert pubs["/fib/result"].msg_class._type == "actionlib_tutorials/FibonacciActionResult"
    assert pubs["/fib/status"].wait_count(1)[0].status_list == []  # start() publishes at once


def test_goal_lifecycle_publishes_result_and_status(h: Harness) -> None:
    h.goal("a", 1.0)
    (handle,) = h.goals
    assert h.statuses() == {"a": S.PENDING}
    handle.set_accepted("go")
    assert h.statuses() == {"a": S.ACTIVE}
    handle.publish_feedback(FibonacciFeedback(sequence=[0, 1]))
    (feedback,) = h.node.pubs["/fib/feedback"].sent
    assert feedback.status.goal_id.id == "a" and feedback.status.status == S.ACTIVE
    assert feedback.feedback.sequence == [0, 1]
    handle.set_succeeded(FibonacciResult(sequence=[0, 1, 1]), "done")
    (result,) = h.results()
    assert result.status.goal_id.id == "a" and result.status.status == S.SUCCEEDED
    assert result.status.text == "done" and result.result.sequence == [0, 1, 1]
    sent = h.node.pubs["/fib/status"].wait_count(2)
    assert sent[-1].status_list[-1].status in (S.ACTIVE, S.SUCCEEDED)


def test_refused_transition_is_one_error_line_and_no_change(h: Harness) -> None:
    h.goal("a", 1.0)
    handle = h.goals[0]
    handle.set_succeeded()  # PENDING cannot succeed
    assert h.statuses() == {"a": S.PENDING}
    assert h.results() == []
    (line,) = h.log.at("error")
    assert "goal a" in line and "from PENDING" in line


def test_goal_without_id_gets_node_named_id_and_stamp(h: Harness) -> None:
    h.goal("")
    goal_id = h.goals[0].get_goal_id()
    assert goal_id.id.startswith("/srv-") and goal_id.stamp == Time.from_sec(100.0)


def test_cancel_everything(h: Harness) -> None:
    h.goal("a", 1.0)
    h.goal("b", 2.0)
    h.goals[1].set_accepted()
    h.cancel()
    assert h.statuses() == {"a": S.RECALLING, "b": S.PREEMPTING}
    assert [c.get_goal_id().id for c in h.cancels] == ["a", "b"]


def test_cancel_by_id(h: Harness) -> None:
    h.goal("a", 1.0)
    h.goal("b", 2.0)
    h.cancel("b")
    assert h.statuses() == {"a": S.PENDING, "b": S.RECALLING}
    h.goals[1].set_canceled()
    assert h.results()[-1].status.status == S.RECALLED


def test_cancel_by_stamp_takes_goals_at_and_before_it(h: Harness) -> None:
    for name, stamp in (("a", 1.0), ("b", 2.0), ("c", 3.0)):
        h.goal(name, stamp)
    h.cancel(stamp=2.0)
    assert h.statuses() == {"a": S.RECALLING, "b": S.RECALLING, "c": S.PENDING}


def test_goal_stamped_before_last_cancel_is_cancelled_on_arrival(h: Harness) -> None:
    h.cancel(stamp=5.0)
    h.goal("old", 4.0)
    h.goal("new", 6.0)
    assert [g.get_goal_id().id for g in h.goals] == ["new"]  # the old one never reached the user
    assert h.statuses()["old"] == S.RECALLED
    assert h.results()[0].status.goal_id.id == "old"


def test_cancel_before_goal_is_remembered_and_recalls_it_on_arrival(h: Harness) -> None:
    h.cancel("early")
    assert h.statuses() == {"early": S.RECALLING}
    (line,) = h.log.at("info")
    assert "early" in line and "remembered" in line
    h.goal("early", 1.0)
    assert h.goals == []  # recalled without bothering the user
    assert h.results()[0].status.status == S.RECALLED
    h.goal("next", 2.0)  # and the server keeps serving
    assert [g.get_goal_id().id for g in h.goals] == ["next"]


def test_repeated_goal_id_is_one_line_and_ignored(h: Harness) -> None:
    h.goal("a", 1.0)
    h.goal("a", 1.0)
    assert len(h.goals) == 1
    (line,) = h.log.at("warn")
    assert "goal id a sent again" in line


def test_terminal_goals_leave_the_status_list_after_the_timeout(h: Harness) -> None:
    h.goal("a", 1.0)
    h.goals[0].set_accepted()
    h.goals[0].set_aborted()
    h.clock.advance(4.9)
    assert h.statuses() == {"a": S.ABORTED}
    h.clock.advance(0.2)
    assert h.statuses() == {}


def test_status_is_published_periodically_on_ros_time() -> None:
    h = Harness(params={"/actionlib_status_frequency": 10.0})
    try:
        status = h.node.pubs["/fib/status"]
        before = len(status.wait_count(1))
        h.clock.advance(0.35)  # wakes the timer: one due tick (late ticks are not replayed)
        status.wait_count(before + 1)
    finally:
        h.server.stop()


def test_parameters_with_wrong_types_fall_back_with_one_line() -> None:
    h = Harness(params={"/fib/status_list_timeout": "soon"})
    try:
        assert h.server.status_list_timeout.to_sec() == 5.0
        (line,) = h.log.at("warn")
        assert "status_list_timeout" in line
    finally:
        h.server.stop()


def test_empty_handle_logs_instead_of_raising() -> None:
    handle = ServerGoalHandle()
    assert handle.get_goal() is None
    handle.set_succeeded()  # one error line on Python logging, no exception
    assert handle != ServerGoalHandle()
