"""SimpleActionServer: one goal at a time, preemption by newer goals, the execute thread's rules."""

from __future__ import annotations

import threading
from typing import Any

from actionlib_fakes import FakeNode, ListLog

from actionlib_msgs.msg import GoalID
from actionlib_tutorials.msg import FibonacciAction, FibonacciActionGoal, FibonacciResult
from ninjemys.actionlib import states as S
from ninjemys.actionlib.simple_server import SimpleActionServer
from ninjemys.node.clock import FakeClock
from ninjemys.rostime import Time


def send(node: FakeNode, goal_id: str, stamp: float, order: int = 1) -> None:
    msg = FibonacciActionGoal()
    msg.goal_id.id = goal_id
    msg.goal_id.stamp = Time.from_sec(stamp)
    msg.goal.order = order
    node.subs["/fib/goal"].deliver(msg)


def make(execute: Any = None) -> tuple[FakeNode, SimpleActionServer, ListLog]:
    node, log = FakeNode("/srv"), ListLog()
    server = SimpleActionServer(node, "fib", FibonacciAction, execute, clock=FakeClock(10.0), log=log)
    server.start()
    return node, server, log


def results(node: FakeNode, n: int) -> list[tuple[str, int]]:
    return [(r.status.goal_id.id, r.status.status) for r in node.pubs["/fib/result"].wait_count(n)]


def test_execute_callback_result() -> None:
    def execute(goal: Any) -> None:
        server.set_succeeded(FibonacciResult(sequence=[goal.order]))

    node, server, _ = make(execute)
    try:
        send(node, "a", 1.0, order=7)
        assert results(node, 1) == [("a", S.SUCCEEDED)]
        assert node.pubs["/fib/result"].sent[0].result.sequence == [7]
    finally:
        server.stop()


def test_newer_goal_preempts_the_running_one() -> None:
    started, release = threading.Event(), threading.Event()
    seen: list[int] = []

    def execute(goal: Any) -> None:
        seen.append(goal.order)
        if goal.order == 1:
            started.set()
            assert release.wait(5)
            assert server.is_preempt_requested() and server.is_new_goal_available()
            server.set_preempted(text="made way")
        else:
            server.set_succeeded()

    node, server, _ = make(execute)
    try:
        send(node, "first", 1.0, order=1)
        assert started.wait(5)
        send(node, "second", 2.0, order=2)
        release.set()
        assert results(node, 2) == [("first", S.PREEMPTED), ("second", S.SUCCEEDED)]
        assert seen == [1, 2]
    finally:
        server.stop()


def test_goal_older_than_the_current_one_is_cancelled_at_once() -> None:
    gate = threading.Event()

    def execute(_goal: Any) -> None:
        assert gate.wait(5)
        server.set_succeeded()

    node, server, _ = make(execute)
    try:
        send(node, "new", 5.0)
        send(node, "stale", 1.0)
        assert results(node, 1) == [("stale", S.RECALLED)]
        gate.set()
        assert results(node, 2)[1] == ("new", S.SUCCEEDED)
    finally:
        server.stop()


def test_execute_without_terminal_state_aborts_with_one_warning() -> None:
    node, server, log = make(lambda goal: None)
    try:
        send(node, "a", 1.0)
        assert results(node, 1) == [("a", S.ABORTED)]
        assert node.pubs["/fib/result"].sent[0].status.text == "No terminal state was set."
        assert len(log.at("warn")) == 1
    finally:
        server.stop()


def test_execute_raising_aborts_and_keeps_serving() -> None:
    def execute(goal: Any) -> None:
        if goal.order == 0:
            raise ValueError("bad order")
        server.set_succeeded()

    node, server, log = make(execute)
    try:
        send(node, "a", 1.0, order=0)
        send_after = results(node, 1)
        assert send_after == [("a", S.ABORTED)]
        assert "bad order" in node.pubs["/fib/result"].sent[0].status.text
        assert any("bad order" in line for line in log.at("error"))
        send(node, "b", 2.0, order=3)
        assert results(node, 2)[1] == ("b", S.SUCCEEDED)
    finally:
        server.stop()


def test_goal_and_preempt_callbacks_mode() -> None:
    node, server, _ = make(None)
    preempts: list[int] = []
    accepted: list[Any] = []
    server.register_goal_callback(lambda: accepted.append(server.accept_new_goal()))
    server.register_preempt_callback(lambda: preempts.append(1))
    try:
        send(node, "a", 1.0, order=4)
        assert [g.order for g in accepted] == [4] and server.is_active()
        node.subs["/fib/cancel"].deliver(GoalID(id="a"))
        assert preempts == [1] and server.is_preempt_requested()
        server.set_preempted()
        assert results(node, 1) == [("a", S.PREEMPTED)]
        assert not server.is_active()
    finally:
        server.stop()


def test_accept_without_new_goal_is_one_error_line() -> None:
    node, server, log = make(None)
    try:
        assert server.accept_new_goal() is None
        assert len(log.at("error")) == 1
    finally:
        server.stop()
