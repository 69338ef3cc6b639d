"""Our action client against our action server over real nodes, topics and a master."""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
from actionlib_fakes import ListLog

from actionlib.msg import TwoIntsAction, TwoIntsGoal, TwoIntsResult
from actionlib_tutorials.msg import FibonacciAction, FibonacciFeedback, FibonacciGoal, FibonacciResult
from ninjemys.actionlib import ActionClient, ActionServer, SimpleActionClient, SimpleActionServer
from ninjemys.actionlib import states as S
from ninjemys.actionlib.states import CommState
from ninjemys.node import Node
from ninjemys.testing import run_master


@pytest.fixture(scope="module")
def master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    env = dict(os.environ, ROS_HOME=str(tmp_path_factory.mktemp("home")), ROS_HOSTNAME="localhost")
    with run_master(env=env) as uri:
        yield uri


@pytest.fixture
def nodes(master: str) -> Iterator[Any]:
    made: list[Node] = []

    def make(name: str) -> Node:
        node = Node(name, master_uri=master)
        made.append(node)
        return node

    yield make
    for node in made:
        node.shutdown()


def adder(node: Node, name: str = "add") -> SimpleActionServer:
    def execute(goal: Any) -> None:
        server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))

    server = SimpleActionServer(node, name, TwoIntsAction, execute)
    server.start()
    return server


def fibonacci_server(node: Node, step: threading.Event | None = None) -> SimpleActionServer:
    """Feedback after each number; between numbers it waits for ``step`` (or not at all)."""

    def execute(goal: Any) -> None:
        seq = [0, 1]
        for _ in range(goal.order):
            if server.is_preempt_requested():
                server.set_preempted(FibonacciResult(sequence=seq), "preempted at %d" % len(seq))
                return
            seq.append(seq[-1] + seq[-2])
            server.publish_feedback(FibonacciFeedback(sequence=seq))
            if step is not None:
                step.wait(0.05)
        server.set_succeeded(FibonacciResult(sequence=seq), "done")

    server = SimpleActionServer(node, "fibonacci", FibonacciAction, execute)
    server.start()
    return server


def test_round_trip_with_all_callbacks(nodes: Any) -> None:
    # 50 ms between feedbacks: feedback and result travel on different topics (threads), and ROS
    # drops feedback that arrives after its goal is done
    fibonacci_server(nodes("server"), step=threading.Event())
    client = SimpleActionClient(nodes("client"), "fibonacci", FibonacciAction)
    assert client.wait_for_server(10.0)
    events: list[Any] = []
    done = threading.Event()
    client.send_goal(
        FibonacciGoal(order=5),
        done_cb=lambda state, result: (events.append(("done", state, list(result.sequence))), done.set()),
        active_cb=lambda: events.append(("active",)),
        feedback_cb=lambda fb: events.append(("feedback", len(fb.sequence))),
    )
    assert client.wait_for_result(10.0) and done.wait(5)
    assert events[0] == ("active",)
    assert [e[1] for e in events if e[0] == "feedback"] == [3, 4, 5, 6, 7]
    assert events[-1] == ("done", S.SUCCEEDED, [0, 1, 1, 2, 3, 5, 8])
    assert client.get_state() == S.SUCCEEDED
    assert client.get_goal_status_text() == "done"
    assert client.get_result().sequence[-1] == 8


def test_wrong_action_name_returns_false_with_one_line(nodes: Any) -> None:
    adder(nodes("server"))
    log = ListLog()
    client = SimpleActionClient(nodes("client"), "ad", TwoIntsAction, log=log)
    started = time.monotonic()
    assert client.wait_for_server(0.5) is False
    assert time.monotonic() - started < 5
    (line,) = log.at("warn")
    assert "/ad/status" in line and "is the action name right" in line


def test_goal_right_after_wait_for_server_never_loses_its_result(nodes: Any) -> None:
    """actionlib#181: a fresh client each time, its goal sent the moment wait_for_server is true."""
    adder(nodes("server"))
    client_node = nodes("client")
    for i in range(20):
        client = SimpleActionClient(client_node, "add", TwoIntsAction)
        assert client.wait_for_server(10.0)
        client.send_goal(TwoIntsGoal(a=i, b=1))
        assert client.wait_for_result(10.0), f"goal {i} lost"
        assert client.get_result().sum == i + 1
        client.action_client.stop()


def test_wait_for_server_waits_until_the_server_lists_our_connections(nodes: Any) -> None:
    """rospy answers a subscriber's handshake before it adds the connection to its publisher, so both
    ends can look connected while a result sent then is lost. The client asks the server's
    getBusInfo: here a server whose bus info leaves our result connection out for its first 0.5 s
    (as a preempted rospy thread would) is not ready before it lists it."""
    server_node = nodes("server")
    adder(server_node)
    real_bus_info = server_node.bus_info
    hide_until = time.monotonic() + 0.5
    asked: list[float] = []

    def lagging_bus_info() -> list[Any]:
        asked.append(time.monotonic())
        rows = real_bus_info()
        if time.monotonic() < hide_until:
            rows = [row for row in rows if not row[4].endswith("/add/result")]
        return rows

    server_node.bus_info = lagging_bus_info  # type: ignore[method-assign]
    client = SimpleActionClient(nodes("client"), "add", TwoIntsAction)
    assert client.wait_for_server(10.0)
    assert time.monotonic() >= hide_until and len(asked) >= 2
    client.send_goal(TwoIntsGoal(a=2, b=3))
    assert client.wait_for_result(10.0) and client.get_result().sum == 5
    asked.clear()
    assert client.wait_for_server(1.0) and asked == []  # confirmed once per server connection


def test_many_goals_back_to_back(nodes: Any) -> None:
    adder(nodes("server"))
    client = SimpleActionClient(nodes("client"), "add", TwoIntsAction)
    for i in range(300):
        assert client.wait_for_server(10.0)
        assert client.send_goal_and_wait(TwoIntsGoal(a=i, b=i), execute_timeout=10.0) == S.SUCCEEDED
        assert client.get_result().sum == 2 * i


def test_cancel_a_running_goal(nodes: Any) -> None:
    hold = threading.Event()
    fibonacci_server(nodes("server"), step=hold)
    client = SimpleActionClient(nodes("client"), "fibonacci", FibonacciAction)
    assert client.wait_for_server(10.0)
    active = threading.Event()
    client.send_goal(FibonacciGoal(order=10_000), active_cb=active.set)
    assert active.wait(10)
    client.cancel_goal()
    assert client.wait_for_result(10.0)
    assert client.get_state() == S.PREEMPTED
    assert client.get_goal_status_text().startswith("preempted at")


def test_send_goal_and_wait_times_out_then_preempts(nodes: Any) -> None:
    fibonacci_server(nodes("server"), step=threading.Event())
    client = SimpleActionClient(nodes("client"), "fibonacci", FibonacciAction)
    assert client.wait_for_server(10.0)
    state = client.send_goal_and_wait(FibonacciGoal(order=10_000), execute_timeout=0.3, preempt_timeout=10.0)
    assert state == S.PREEMPTED


def test_done_callback_may_send_the_next_goal(nodes: Any) -> None:
    adder(nodes("server"))
    client = SimpleActionClient(nodes("client"), "add", TwoIntsAction)
    assert client.wait_for_server(10.0)
    sums: list[int] = []
    finished = threading.Event()

    def done(_state: int, result: Any) -> None:
        sums.append(result.sum)
        if len(sums) < 5:
            client.send_goal(TwoIntsGoal(a=len(sums), b=0), done_cb=done)
        else:
            finished.set()

    client.send_goal(TwoIntsGoal(a=0, b=0), done_cb=done)
    assert finished.wait(10)
    assert sums == [0, 1, 2, 3, 4]


def test_action_client_tracks_many_goals_and_cancel_rules(nodes: Any) -> None:
    """Plain ActionServer/ActionClient: several goals at once, cancelled by stamp and then all."""
    handles: list[Any] = []
    server = ActionServer(
        nodes("server"), "multi", TwoIntsAction, lambda gh: (gh.set_accepted(), handles.append(gh))
    )
    server.register_cancel_callback(lambda gh: gh.set_canceled(None, "cancelled"))
    server.start()
    client = ActionClient(nodes("client"), "multi", TwoIntsAction)
    assert client.wait_for_server(10.0)
    goals = []
    for i in range(4):
        goals.append(client.send_goal(TwoIntsGoal(a=i, b=0)))
        time.sleep(0.01)  # distinct stamps
    deadline = time.monotonic() + 10
    while len(handles) < 4 or any(g.get_comm_state() != CommState.ACTIVE for g in goals):
        assert time.monotonic() < deadline, [CommState.to_string(g.get_comm_state()) for g in goals]
        time.sleep(0.01)
    client.cancel_goals_at_and_before_time(goals[1].comm_state_machine.action_goal.goal_id.stamp)
    while goals[1].get_comm_state() != CommState.DONE:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert [g.get_goal_status() for g in goals[:2]] == [S.PREEMPTED, S.PREEMPTED]
    assert [g.get_comm_state() for g in goals[2:]] == [CommState.ACTIVE, CommState.ACTIVE]
    client.cancel_all_goals()
    while any(g.get_comm_state() != CommState.DONE for g in goals):
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert [g.get_terminal_state() for g in goals] == [S.PREEMPTED] * 4


def test_goal_storm_preempting_each_other_ends_every_goal(nodes: Any) -> None:
    """Goals arriving while others execute, each preempting the previous: locks never cross, and
    every goal ends PREEMPTED or RECALLED once all are cancelled."""

    def execute(_goal: Any) -> None:
        while not server.is_preempt_requested():
            time.sleep(0.001)
        server.set_preempted()

    server = SimpleActionServer(nodes("server"), "storm", TwoIntsAction, execute)
    server.start()
    client = ActionClient(nodes("client"), "storm", TwoIntsAction)
    assert client.wait_for_server(10.0)
    goals = [client.send_goal(TwoIntsGoal(a=i)) for i in range(150)]
    time.sleep(0.2)
    client.cancel_all_goals()
    deadline = time.monotonic() + 20
    while any(g.get_comm_state() != CommState.DONE for g in goals):
        assert time.monotonic() < deadline, [
            (i, CommState.to_string(g.get_comm_state()), g.get_goal_status())
            for i, g in enumerate(goals)
            if g.get_comm_state() != CommState.DONE
        ]
        time.sleep(0.02)
    assert {g.get_terminal_state() for g in goals} <= {S.PREEMPTED, S.RECALLED}
