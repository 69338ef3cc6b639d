"""smach's exceptions. As in smach, each one logs its message through smach's error logger when it is
created, so a failure inside a state machine is visible even if user code swallows the exception."""

from __future__ import annotations

from ninjemys.errors import NinjemysError
from ninjemys.smach.log import logerr

__all__ = [
    "InvalidConstructionError",
    "InvalidStateError",
    "InvalidTransitionError",
    "InvalidUserCodeError",
    "SmachError",
]


class SmachError(NinjemysError):
    """Root of smach's errors; the message is logged as ``<ClassName>: <message>``."""

    def __init__(self, message: str) -> None:
        logerr(f"{type(self).__name__}: {message}")
        super().__init__(message)


class InvalidTransitionError(SmachError):
    """An outcome leads nowhere: unregistered, unbound, or to an unknown state."""


class InvalidStateError(SmachError):
    """A container was built or used wrongly (duplicate label, nothing opened, no children)."""


class InvalidUserCodeError(SmachError):
    """User code (a state's execute, a callback) raised, or touched undeclared userdata keys."""


class InvalidConstructionError(SmachError):
    """A construction method was called on a container that is not open."""
