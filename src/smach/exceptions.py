"""``smach.exceptions``, as in smach: where its error classes live (and are named from in tracebacks)."""

from ninjemys.smach.errors import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
    SmachError,
)

__all__ = [
    "InvalidConstructionError",
    "InvalidStateError",
    "InvalidTransitionError",
    "InvalidUserCodeError",
    "SmachError",
]
