"""rospy's exception classes, and the one place ninjemys errors become them.

The core raises the :mod:`ninjemys.errors` tree; user code written for rospy catches these names. The
facade converts at its boundary with :func:`translate` / :func:`mapped`, so ``except
rospy.ROSInterruptException`` keeps working around ``rate.sleep()`` and ``rospy.ServiceException``
around service calls.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


class ROSException(Exception):
    """Base exception class for ROS clients."""


class ROSSerializationException(ROSException):
    """A message could not be serialized (wrong field type or value)."""


class PublishArgumentError(ROSSerializationException, TypeError):
    """``publish()`` arguments that do not make a message of the topic's type.

    rospy raises a plain TypeError here (``pub.publish(Int32(3))`` on a String topic, or too many
    arguments); ninjemys used to raise ROSSerializationException. This is both, so code written
    against either catches it.
    """


class ROSInitException(ROSException):
    """The node could not be initialized (bad arguments, master unreachable, ...)."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """An operation was interrupted because the node is shutting down (Ctrl-C, rosnode kill, ...)."""


class ROSTimeMovedBackwardsException(ROSInterruptException):
    """ROS time jumped backwards during a sleep (simulated time restarted, e.g. a looping bag)."""

    def __init__(self, time: float = 0.0) -> None:
        self.time = time
        super().__init__("ROS time moved backwards")


class ROSInternalException(Exception):
    """A bug in the client library, not in the user's code."""


class TransportException(ROSException):
    """Something went wrong in the transport layer."""


class TransportInitError(TransportException):
    """A transport could not be initialized."""


class TransportTerminated(TransportException):
    """The transport connection ended."""


class ServiceException(ROSException):
    """A service call failed, or a service handler reported an error."""


class ServiceArgumentError(ServiceException, TypeError):
    """A ServiceProxy called with arguments that make no request: rospy raises TypeError, ninjemys
    raised ServiceException; this is both."""


class NotAServiceClassError(ValueError, AttributeError):
    """A class given as a service type is not one: rospy fails with an AttributeError, ninjemys
    raised ValueError; this is both."""


def translate(exc: BaseException) -> BaseException:
    """The rospy exception that stands for ``exc`` (``exc`` itself when it is not a ninjemys error)."""
    from ninjemys import errors

    if not isinstance(exc, errors.NinjemysError):
        return exc
    text = str(exc)
    if type(exc).__name__ == "TimeMovedBackwardsError":
        return ROSTimeMovedBackwardsException(getattr(exc, "time_after", 0.0))
    if isinstance(exc, errors.ShutdownError):
        return ROSInterruptException(text)
    if isinstance(exc, errors.ServiceError):
        return ServiceArgumentError(text) if isinstance(exc, TypeError) else ServiceException(text)
    if isinstance(exc, errors.SerializationError):
        return ROSSerializationException(text)
    if isinstance(exc, errors.NameError_):
        return ValueError(text)
    if isinstance(exc, errors.MasterUnreachable) and exc.cause is not None:
        return _socket_error(exc.cause)
    return ROSException(text)


def _socket_error(cause: OSError) -> OSError:
    """What rospy raises when the master cannot be reached: its XML-RPC proxy's socket error, as it
    came (``ConnectionRefusedError: [Errno 111] Connection refused`` when no master runs). A new
    instance of the same class: the original's traceback runs through our client's frames."""
    try:
        if cause.errno is not None and cause.strerror is not None:
            return type(cause)(cause.errno, cause.strerror)
        return type(cause)(*cause.args)
    except TypeError:  # an OSError subclass with another constructor
        return OSError(cause.errno, cause.strerror)


@contextmanager
def mapped() -> Iterator[None]:
    """Run a block, re-raising ninjemys errors as their rospy counterparts (traceback kept short)."""
    from ninjemys.errors import NinjemysError

    try:
        yield
    except NinjemysError as exc:
        raise translate(exc) from None
