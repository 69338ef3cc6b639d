"""smach's exceptions. As in smach, each one logs its message through smach's error logger when it is
created, so a failure inside a state machine is visible even if user code swallows the exception.

What users see is smach's, not ours: the classes print as ``smach.exceptions.InvalidUserCodeError``
(the module ``smach.exceptions`` holds them, as in smach), and the traceback that "Could not execute
state ..." carries (:func:`user_traceback`) starts at the user's code, without the container frames
of this package that led there. The error that user code raised stays on ``__context__``; it is not
printed a second time above the message that already shows it."""

from __future__ import annotations

import sys
import traceback
from pathlib import Path

from ninjemys.errors import NinjemysError
from ninjemys.smach.log import logerr

__all__ = [
    "InvalidConstructionError",
    "InvalidStateError",
    "InvalidTransitionError",
    "InvalidUserCodeError",
    "SmachError",
]


#: where this package's frames come from (left out of the tracebacks user code's errors carry)
_HERE = str(Path(__file__).resolve().parent)


def user_traceback(exc: BaseException | None = None) -> str:
    """``traceback.format_exc()`` (of ``exc``, or of the exception being handled) without the frames
    of the smach machinery in this package: the user's own code is what a reader needs."""
    if exc is None:
        exc = sys.exc_info()[1]
        if exc is None:
            return "NoneType: None\n"
    shown = traceback.TracebackException.from_exception(exc)
    kept = [frame for frame in shown.stack if not str(Path(frame.filename).resolve()).startswith(_HERE)]
    shown.stack = traceback.StackSummary.from_list(kept or list(shown.stack))
    return "".join(shown.format())


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


for _cls in (
    SmachError,
    InvalidTransitionError,
    InvalidStateError,
    InvalidUserCodeError,
    InvalidConstructionError,
):
    _cls.__module__ = "smach.exceptions"  # how tracebacks name them: smach's module, which re-exports them
