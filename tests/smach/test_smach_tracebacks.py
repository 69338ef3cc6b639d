"""What a user sees when a state fails: smach's names (``smach.exceptions.InvalidUserCodeError``,
importable from ``smach.exceptions``), the traceback of the user's own code in the message without
the container frames of ninjemys that led to it, and that traceback printed once, not twice."""

from __future__ import annotations

import subprocess
import sys
import traceback
from pathlib import Path

import pytest

import smach
from smach.exceptions import InvalidTransitionError, InvalidUserCodeError


@pytest.fixture(autouse=True)
def quiet_logs() -> list[str]:
    lines: list[str] = []
    smach.set_loggers(lines.append, lines.append, lines.append, lines.append)
    smach.set_shutdown_check(lambda: False)
    return lines


class Divides(smach.State):
    def __init__(self) -> None:
        super().__init__(outcomes=["done"], input_keys=["x"])

    def execute(self, ud):
        return 1 / ud.x  # the line the user must see


def _machine(state: smach.State) -> smach.StateMachine:
    sm = smach.StateMachine(outcomes=["end"])
    sm.userdata.x = 0
    with sm:
        smach.StateMachine.add("STATE", state, transitions={"done": "end"})
    return sm


def test_a_failing_state_names_the_users_line_not_ours(quiet_logs: list[str]) -> None:
    with pytest.raises(InvalidUserCodeError) as caught:
        _machine(Divides()).execute()
    err = caught.value
    message = str(err)
    assert message.startswith("Could not execute state 'STATE' of type '<")
    assert f'File "{__file__}"' in message and "return 1 / ud.x" in message
    assert message.rstrip().endswith("ZeroDivisionError: division by zero")
    assert "ninjemys" not in message  # no frame of the machinery
    assert isinstance(err.__context__, ZeroDivisionError) and err.__cause__ is None
    printed = "".join(traceback.format_exception(err))
    assert "smach.exceptions.InvalidUserCodeError: Could not execute state 'STATE'" in printed
    assert "During handling" not in printed and "direct cause" not in printed  # the traceback once
    assert printed.count("ZeroDivisionError: division by zero") == 1
    assert any(
        line.startswith("InvalidUserCodeError: Could not execute state 'STATE'") for line in quiet_logs
    )


def test_smach_exceptions_is_smachs_module() -> None:
    assert InvalidUserCodeError is smach.InvalidUserCodeError
    assert InvalidTransitionError.__module__ == "smach.exceptions"
    assert issubclass(InvalidUserCodeError, smach.exceptions.SmachError)


def test_an_unregistered_outcome_prints_as_smachs_error(tmp_path: Path) -> None:
    script = tmp_path / "machine.py"
    script.write_text(
        "import smach\n"
        "class Odd(smach.State):\n"
        "    def __init__(self):\n"
        "        smach.State.__init__(self, outcomes=['done'])\n"
        "    def execute(self, ud):\n"
        "        return 'nope'\n"
        "sm = smach.StateMachine(outcomes=['end'])\n"
        "with sm:\n"
        "    smach.StateMachine.add('ODD', Odd(), transitions={'done': 'end'})\n"
        "sm.execute()\n"
    )
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("smach.exceptions.InvalidTransitionError: Attempted to return outcome 'nope'")
