"""The state vocabularies of the action protocol, and the client's communication state machine.

``GoalStatus`` codes are what travels on the wire (actionlib_msgs/GoalStatus); ``CommState`` is what a
client knows about one of its goals; ``SimpleGoalState`` is the three-state view SimpleActionClient
gives its user. :func:`comm_transitions` is the client's table: for the state a goal is in and the
status the server reports, the states to pass through (in order). It is pure data, so the whole
client machine is testable without a node.
"""

from __future__ import annotations

# actionlib_msgs/GoalStatus codes (the wire values)
PENDING = 0
ACTIVE = 1
PREEMPTED = 2
SUCCEEDED = 3
ABORTED = 4
REJECTED = 5
PREEMPTING = 6
RECALLING = 7
RECALLED = 8
LOST = 9

STATUS_NAMES = {
    PENDING: "PENDING",
    ACTIVE: "ACTIVE",
    PREEMPTED: "PREEMPTED",
    SUCCEEDED: "SUCCEEDED",
    ABORTED: "ABORTED",
    REJECTED: "REJECTED",
    PREEMPTING: "PREEMPTING",
    RECALLING: "RECALLING",
    RECALLED: "RECALLED",
    LOST: "LOST",
}

#: the statuses after which a goal never changes again
TERMINAL_STATUSES = frozenset({PREEMPTED, SUCCEEDED, ABORTED, REJECTED, RECALLED, LOST})


def _name_of(cls: type, value: int) -> str:
    """ROS 1's ``to_string``: the constant's name, or ``NO_SUCH_STATE_<n>``."""
    for key, item in vars(cls).items():
        if not key.startswith("_") and isinstance(item, int) and item == value:
            return key
    return f"NO_SUCH_STATE_{value}"


class CommState:
    """What a client knows about one goal (actionlib's CommState, same numbers)."""

    WAITING_FOR_GOAL_ACK = 0
    PENDING = 1
    ACTIVE = 2
    WAITING_FOR_RESULT = 3
    WAITING_FOR_CANCEL_ACK = 4
    RECALLING = 5
    PREEMPTING = 6
    DONE = 7
    LOST = 8

    @classmethod
    def to_string(cls, n: int) -> str:
        return _name_of(cls, n)


class TerminalState:
    """The statuses a finished goal can end in (their GoalStatus codes)."""

    RECALLED = RECALLED
    REJECTED = REJECTED
    PREEMPTED = PREEMPTED
    ABORTED = ABORTED
    SUCCEEDED = SUCCEEDED
    LOST = LOST

    @classmethod
    def to_string(cls, n: int) -> str:
        return _name_of(cls, n)


class SimpleGoalState:
    """SimpleActionClient's view of its one goal."""

    PENDING = 0
    ACTIVE = 1
    DONE = 2

    @classmethod
    def to_string(cls, n: int) -> str:
        return _name_of(cls, n)


def status_name(value: int) -> str:
    return STATUS_NAMES.get(value, f"NO_SUCH_STATE_{value}")


#: marker: the reported status is legal here and changes nothing
STAY = ()
#: marker: the server reported a status this state cannot lead to (logged, ignored)
INVALID = None

_C = CommState
# For each CommState: reported GoalStatus -> the CommStates to pass through, in order. A server may
# skip states a client never saw (a goal accepted and finished between two status messages), so a
# report can imply several transitions; the client runs each (and the user sees each callback).
_TABLE: dict[int, dict[int, tuple[int, ...] | None]] = {
    _C.WAITING_FOR_GOAL_ACK: {
        PENDING: (_C.PENDING,),
        ACTIVE: (_C.ACTIVE,),
        REJECTED: (_C.PENDING, _C.WAITING_FOR_RESULT),
        RECALLING: (_C.PENDING, _C.RECALLING),
        RECALLED: (_C.PENDING, _C.WAITING_FOR_RESULT),
        PREEMPTED: (_C.ACTIVE, _C.PREEMPTING, _C.WAITING_FOR_RESULT),
        SUCCEEDED: (_C.ACTIVE, _C.WAITING_FOR_RESULT),
        ABORTED: (_C.ACTIVE, _C.WAITING_FOR_RESULT),
        PREEMPTING: (_C.ACTIVE, _C.PREEMPTING),
    },
    _C.PENDING: {
        PENDING: STAY,
        ACTIVE: (_C.ACTIVE,),
        REJECTED: (_C.WAITING_FOR_RESULT,),
        RECALLING: (_C.RECALLING,),
        RECALLED: (_C.RECALLING, _C.WAITING_FOR_RESULT),
        PREEMPTED: (_C.ACTIVE, _C.PREEMPTING, _C.WAITING_FOR_RESULT),
        SUCCEEDED: (_C.ACTIVE, _C.WAITING_FOR_RESULT),
        ABORTED: (_C.ACTIVE, _C.WAITING_FOR_RESULT),
        PREEMPTING: (_C.ACTIVE, _C.PREEMPTING),
    },
    _C.ACTIVE: {
        PENDING: INVALID,
        ACTIVE: STAY,
        REJECTED: INVALID,
        RECALLING: INVALID,
        RECALLED: INVALID,
        PREEMPTED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        SUCCEEDED: (_C.WAITING_FOR_RESULT,),
        ABORTED: (_C.WAITING_FOR_RESULT,),
        PREEMPTING: (_C.PREEMPTING,),
    },
    _C.WAITING_FOR_RESULT: {
        PENDING: INVALID,
        ACTIVE: STAY,
        REJECTED: STAY,
        RECALLING: INVALID,
        RECALLED: STAY,
        PREEMPTED: STAY,
        SUCCEEDED: STAY,
        ABORTED: STAY,
        PREEMPTING: INVALID,
    },
    _C.WAITING_FOR_CANCEL_ACK: {
        PENDING: STAY,
        ACTIVE: STAY,
        REJECTED: (_C.WAITING_FOR_RESULT,),
        RECALLING: (_C.RECALLING,),
        RECALLED: (_C.RECALLING, _C.WAITING_FOR_RESULT),
        PREEMPTED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        SUCCEEDED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        ABORTED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        PREEMPTING: (_C.PREEMPTING,),
    },
    _C.RECALLING: {
        PENDING: INVALID,
        ACTIVE: INVALID,
        REJECTED: (_C.WAITING_FOR_RESULT,),
        RECALLING: STAY,
        RECALLED: (_C.WAITING_FOR_RESULT,),
        PREEMPTED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        SUCCEEDED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        ABORTED: (_C.PREEMPTING, _C.WAITING_FOR_RESULT),
        PREEMPTING: (_C.PREEMPTING,),
    },
    _C.PREEMPTING: {
        PENDING: INVALID,
        ACTIVE: INVALID,
        REJECTED: INVALID,
        RECALLING: INVALID,
        RECALLED: INVALID,
        PREEMPTED: (_C.WAITING_FOR_RESULT,),
        SUCCEEDED: (_C.WAITING_FOR_RESULT,),
        ABORTED: (_C.WAITING_FOR_RESULT,),
        PREEMPTING: STAY,
    },
    _C.DONE: {
        PENDING: INVALID,
        ACTIVE: INVALID,
        REJECTED: STAY,
        RECALLING: INVALID,
        RECALLED: STAY,
        PREEMPTED: STAY,
        SUCCEEDED: STAY,
        ABORTED: STAY,
        PREEMPTING: INVALID,
    },
}


def comm_transitions(state: int, status: int) -> tuple[int, ...] | None:
    """The CommStates a goal in ``state`` passes through when the server reports ``status``.

    ``()`` means no change; ``None`` means the report is impossible from this state (a server bug or
    a reordering), and ``KeyError`` means the status code is not one of the nine a server may send.
    """
    return _TABLE[state][status]
