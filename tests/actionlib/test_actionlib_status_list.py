"""``ActionServer.status_list``: ROS 1's list of the goals' trackers, live (programs and ROS 1's own
tests edit it to drop a goal)."""

from __future__ import annotations

from actionlib_fakes import FakeNode, ListLog

from actionlib_tutorials.msg import FibonacciAction, FibonacciActionGoal
from ninjemys.actionlib import states as S
from ninjemys.actionlib.server import ActionServer
from ninjemys.node.clock import FakeClock
from ninjemys.rostime import Time


def make_server() -> tuple[ActionServer, FakeNode]:
    node = FakeNode("/srv", None)
    server = ActionServer(
        node, "fib", FibonacciAction, lambda h: h.set_accepted(), clock=FakeClock(100.0), log=ListLog()
    )
    server.start()
    return server, node


def send(node: FakeNode, goal_id: str, stamp: float) -> None:
    msg = FibonacciActionGoal()
    msg.goal_id.id = goal_id
    msg.goal_id.stamp = Time.from_sec(stamp)
    node.subs["/fib/goal"].deliver(msg)


def listed(server: ActionServer) -> dict[str, int]:
    return {s.goal_id.id: s.status for s in server._status_array().status_list}


def test_edits_change_the_goals_the_server_lists() -> None:
    server, node = make_server()
    try:
        for i, goal_id in enumerate(("a", "b", "c")):
            send(node, goal_id, float(i))
        status_list = server.status_list
        assert len(status_list) == 3 and [t.status.goal_id.id for t in status_list] == ["a", "b", "c"]
        for i, tracker in enumerate(status_list):  # iterating a snapshot: deleting while looping is safe
            if tracker.status.goal_id.id == "b":
                del status_list[i]
        assert listed(server) == {"a": S.ACTIVE, "c": S.ACTIVE}
        removed = server.trackers["a"]
        del server.status_list[0]
        server.status_list.insert(0, removed)
        assert [t.status.goal_id.id for t in server.status_list] == ["a", "c"]
        server.status_list[1] = removed
        assert list(server.trackers) == ["a"]
    finally:
        server.stop()


def test_a_pending_merged_status_goes_out_before_an_edit() -> None:
    """Clients must see the goal ACTIVE before it vanishes (then they mark it LOST, as in ROS 1)."""
    server, node = make_server()
    try:
        send(node, "first", 0.0)
        send(node, "second", 1.0)  # within the merge interval: its ACTIVE status waits for a merged list
        before = len(node.pubs["/fib/status"].sent)
        del server.status_list[1]
        sent = node.pubs["/fib/status"].sent
        assert len(sent) == before + 1
        assert {s.goal_id.id: s.status for s in sent[-1].status_list}["second"] == S.ACTIVE
        assert "second" not in listed(server)
    finally:
        server.stop()
