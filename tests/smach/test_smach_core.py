"""smach's core without ROS: containers, userdata declarations and remapping, preemption, errors."""

from __future__ import annotations

import threading
import time

import pytest

import smach


@pytest.fixture(autouse=True)
def quiet_logs() -> list[tuple[str, str]]:
    lines: list[tuple[str, str]] = []
    smach.set_loggers(
        lambda m: lines.append(("info", m)),
        lambda m: lines.append(("warn", m)),
        lambda m: lines.append(("debug", m)),
        lambda m: lines.append(("error", m)),
    )
    smach.set_shutdown_check(lambda: False)
    return lines


class Counter(smach.State):
    def __init__(self, limit: int) -> None:
        super().__init__(outcomes=["again", "done"], input_keys=["n"], output_keys=["n"])
        self.limit = limit

    def execute(self, ud):
        ud.n = ud.n + 1
        return "again" if ud.n < self.limit else "done"


class Returns(smach.State):
    def __init__(self, outcome: str, outcomes: list[str] | None = None) -> None:
        super().__init__(outcomes=outcomes or [outcome])
        self.outcome = outcome
        self.ran = 0

    def execute(self, ud):
        self.ran += 1
        return self.outcome


class Blocks(smach.State):
    """Runs until preempted (services the preempt) or released."""

    def __init__(self) -> None:
        super().__init__(outcomes=["done", "preempted"])
        self.started = threading.Event()
        self.release = threading.Event()

    def execute(self, ud):
        self.started.set()
        while not self.release.wait(0.01):
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
        return "done"


def test_state_machine_loops_with_remapping_and_logs_transitions(quiet_logs) -> None:
    sm = smach.StateMachine(outcomes=["finished"], input_keys=["start"], output_keys=["start"])
    with sm:
        smach.StateMachine.add(
            "COUNT", Counter(3), transitions={"again": "COUNT", "done": "finished"}, remapping={"n": "start"}
        )
    parent = smach.UserData()
    parent.start = 0
    outcome = sm.execute(smach.Remapper(parent, ["start"], ["start"], {}))
    assert outcome == "finished"
    assert parent.start == 3
    infos = [m for kind, m in quiet_logs if kind == "info"]
    assert "State machine starting in initial state 'COUNT' with userdata: \n\t['start']" in infos
    assert infos.count("State machine transitioning 'COUNT':'again'-->'COUNT'") == 2
    assert "State machine terminating 'COUNT':'done':'finished'" in infos


def test_add_auto_and_sequence_chain_states() -> None:
    sm = smach.StateMachine(outcomes=["ok", "bad"])
    with sm:
        smach.StateMachine.add_auto(
            "A", Returns("next", ["next", "fail"]), ["next"], transitions={"fail": "bad"}
        )
        smach.StateMachine.add("B", Returns("ok"))
    assert sm.execute() == "ok"
    assert ("next", "A", "B") in sm.get_internal_edges()

    seq = smach.Sequence(outcomes=["succeeded", "aborted"], connector_outcome="succeeded")
    states = [Returns("succeeded", ["succeeded", "aborted"]) for _ in range(3)]
    with seq:
        for i, s in enumerate(states):
            smach.Sequence.add(f"S{i}", s)
    assert seq.execute() == "succeeded"
    assert [s.ran for s in states] == [1, 1, 1]


def test_userdata_declarations_are_enforced(quiet_logs) -> None:
    class ReadsUndeclared(smach.State):
        def __init__(self) -> None:
            super().__init__(outcomes=["done"])

        def execute(self, ud):
            return ud.secret

    sm = smach.StateMachine(outcomes=["done"])
    sm.userdata.secret = 1
    with sm:
        smach.StateMachine.add("R", ReadsUndeclared())
    with pytest.raises(smach.InvalidUserCodeError, match="Reading from SMACH userdata key 'secret'"):
        sm.execute()

    class Writes(smach.State):
        def __init__(self) -> None:
            super().__init__(outcomes=["done"], input_keys=["obj"])

        def execute(self, ud):
            ud.out = 5  # undeclared output: logged, ignored
            with pytest.raises(TypeError):
                ud.obj.value = 2  # input-only objects are read-only
            return "done"

    class Obj:
        value = 1

    sm2 = smach.StateMachine(outcomes=["done"])
    sm2.userdata.obj = Obj()
    with sm2:
        smach.StateMachine.add("W", Writes())
    assert sm2.execute() == "done"
    assert "out" not in sm2.userdata
    assert sm2.userdata.obj.value == 1
    assert any("Writing to SMACH userdata key 'out'" in m for kind, m in quiet_logs if kind == "error")


def test_construction_errors_name_the_problem(quiet_logs) -> None:
    sm = smach.StateMachine(outcomes=["done"])
    with pytest.raises(smach.InvalidStateError, match="no container is opened"):
        smach.StateMachine.add("A", Returns("done"))
    with pytest.raises(smach.InvalidTransitionError, match="Specified outcome 'nope' on state 'A'"):
        with sm:
            smach.StateMachine.add("A", Returns("done"), transitions={"nope": "done"})
    assert not smach.Container._construction_stack  # the failed construction did not leave sm open
    with sm:
        smach.StateMachine.add("A", Returns("done"), transitions={"done": "MISSING"})
    assert "Container consistency check failed." in [m for kind, m in quiet_logs if kind == "error"]
    assert sm.execute() is None
    with pytest.raises(
        smach.InvalidStateError, match='label "A" to state machine, but this label is already'
    ):
        with sm:
            smach.StateMachine.add("A", Returns("done"))


def test_unregistered_outcome_and_user_exceptions() -> None:
    class Liar(smach.State):
        def __init__(self) -> None:
            super().__init__(outcomes=["ok"])

        def execute(self, ud):
            return "surprise"

    sm = smach.StateMachine(outcomes=["ok"])
    with sm:
        smach.StateMachine.add("L", Liar())
    with pytest.raises(
        smach.InvalidTransitionError, match="Attempted to return outcome 'surprise' from state 'L'"
    ):
        sm.execute()

    def boom(ud):
        raise RuntimeError("boom")

    sm2 = smach.StateMachine(outcomes=["ok"])
    with sm2:
        smach.StateMachine.add("B", smach.CBState(boom, outcomes=["ok"]))
    with pytest.raises(smach.InvalidUserCodeError, match="Could not execute state 'B'") as info:
        sm2.execute()
    assert "RuntimeError: boom" in str(info.value)
    assert isinstance(info.value, smach.SmachError)
    from ninjemys.errors import NinjemysError

    assert isinstance(info.value, NinjemysError)


def test_cb_state_with_cb_interface() -> None:
    @smach.cb_interface(outcomes=["big", "small"], input_keys=["x"], output_keys=["y"])
    def classify(ud, threshold):
        ud.y = ud.x * 2
        return "big" if ud.x > threshold else "small"

    state = smach.CBState(classify, cb_args=[10])
    assert set(state.get_registered_outcomes()) == {"big", "small"}
    sm = smach.StateMachine(outcomes=["big", "small"])
    sm.userdata.x = 11
    with sm:
        smach.StateMachine.add("C", state)
    assert sm.execute() == "big"
    assert sm.userdata.y == 22


def test_preempt_stops_a_state_machine_and_is_serviced() -> None:
    blocker = Blocks()
    after = Returns("done")
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    with sm:
        smach.StateMachine.add("BLOCK", blocker, transitions={"done": "AFTER", "preempted": "preempted"})
        smach.StateMachine.add("AFTER", after)
    result: list[str | None] = []
    t = threading.Thread(target=lambda: result.append(sm.execute()))
    t.start()
    assert blocker.started.wait(5)
    assert sm.is_running()
    sm.request_preempt()
    t.join(5)
    assert result == ["preempted"]
    assert after.ran == 0
    assert not sm.preempt_requested()


def test_concurrence_outcome_map_child_termination_and_outcome_cb() -> None:
    fast = Returns("done", ["done", "preempted"])
    slow = Blocks()
    seen: list[dict] = []

    def child_term(outcomes):
        seen.append(dict(outcomes))
        return outcomes.get("FAST") == "done"

    cc = smach.Concurrence(
        outcomes=["ok", "partial", "preempted"],
        default_outcome="partial",
        outcome_map={"ok": {"FAST": "done", "SLOW": "preempted"}},
        child_termination_cb=child_term,
    )
    with cc:
        smach.Concurrence.add("FAST", fast)
        smach.Concurrence.add("SLOW", slow)
    assert cc.execute() == "ok"
    assert seen[0] == {"FAST": "done", "SLOW": None}
    assert ("done", "FAST", "ok") in cc.get_internal_edges()

    cc2 = smach.Concurrence(
        outcomes=["a", "b"],
        default_outcome="a",
        outcome_cb=lambda outcomes: "b" if outcomes["X"] == "done" else None,
    )
    with cc2:
        smach.Concurrence.add("X", Returns("done"))
        smach.Concurrence.add("Y", Returns("done"))
    assert cc2.execute() == "b"


def test_concurrence_preempt_and_policy_errors() -> None:
    b1, b2 = Blocks(), Blocks()
    cc = smach.Concurrence(outcomes=["done", "preempted"], default_outcome="done")
    with cc:
        smach.Concurrence.add("B1", b1)
        smach.Concurrence.add("B2", b2)
    result: list[str | None] = []
    t = threading.Thread(target=lambda: result.append(cc.execute()))
    t.start()
    assert b1.started.wait(5) and b2.started.wait(5)
    cc.request_preempt()
    t.join(5)
    assert result == ["preempted"]
    with pytest.raises(smach.InvalidStateError, match="Default outcome 'x' is unregistered"):
        smach.Concurrence(outcomes=["done"], default_outcome="x")


def test_iterator_runs_per_item_and_breaks() -> None:
    seen: list[int] = []

    @smach.cb_interface(outcomes=["continue", "stop"], input_keys=["item"])
    def body(ud):
        seen.append(ud.item)
        return "stop" if ud.item == 3 else "continue"

    it = smach.Iterator(
        outcomes=["found"],
        input_keys=[],
        output_keys=[],
        it=lambda: range(10),
        it_label="item",
        exhausted_outcome="none",
    )
    with it:
        smach.Iterator.set_contained_state(
            "BODY", smach.CBState(body), loop_outcomes=["continue"], final_outcome_map={"stop": "found"}
        )
    assert it.execute() == "found"
    assert seen == [0, 1, 2, 3]
    seen.clear()
    it2 = smach.Iterator(outcomes=[], input_keys=[], output_keys=[], it=[5, 6], it_label="item")
    with it2:
        smach.Iterator.set_contained_state("BODY", smach.CBState(body), loop_outcomes=["continue"])
    assert it2.execute() == "exhausted"
    assert seen == [5, 6]


def test_callbacks_and_nested_containers() -> None:
    events: list[tuple] = []
    inner = smach.StateMachine(outcomes=["inner_done"])
    with inner:
        smach.StateMachine.add("I1", Returns("x"), transitions={"x": "I2"})
        smach.StateMachine.add("I2", Returns("inner_done"))
    outer = smach.StateMachine(outcomes=["all_done"])
    with outer:
        smach.StateMachine.add("SUB", inner, transitions={"inner_done": "all_done"})
    outer.register_start_cb(lambda ud, initial: events.append(("start", tuple(initial))))
    inner.register_transition_cb(lambda ud, active: events.append(("inner", tuple(active))))
    outer.register_termination_cb(
        lambda ud, terminal, outcome: events.append(("end", tuple(terminal), outcome))
    )
    assert outer.execute() == "all_done"
    assert events == [("start", ("SUB",)), ("inner", ("I2",)), ("end", ("SUB",), "all_done")]
    assert outer["SUB"] is inner


def test_shutdown_check_stops_between_states() -> None:
    stop = threading.Event()

    class SetsStop(smach.State):
        def __init__(self) -> None:
            super().__init__(outcomes=["again"])

        def execute(self, ud):
            stop.set()
            return "again"

    smach.set_shutdown_check(stop.is_set)
    sm = smach.StateMachine(outcomes=["never"])
    with sm:
        smach.StateMachine.add("S", SetsStop(), transitions={"again": "S"})
    started = time.monotonic()
    assert sm.execute() is None
    assert time.monotonic() - started < 5
