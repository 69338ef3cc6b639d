"""The one exception tree of ninjemys.

Every error the library raises on purpose derives from :class:`NinjemysError`, so callers can catch
"anything ninjemys complained about" without also catching programming errors. The tree::

    NinjemysError
    +-- DefinitionError          a .msg/.srv/.action text is malformed (carries file and line)
    +-- TypeNotFoundError        an interface type or package could not be found (says where it looked)
    +-- SerializationError       a message field holds a value of the wrong type or range
    +-- DeserializationError     bytes do not decode as the expected message (truncated, bogus length)
    +-- NameError_               a graph name is invalid (named with a trailing _ to not shadow the builtin)
    +-- ProtocolError            a peer broke the TCPROS / XML-RPC protocol (bad header, md5 mismatch)
    +-- MasterError              the master could not be reached or answered with a failure code
    |   +-- MasterUnreachable
    +-- ParameterError           a parameter is unset or has an unusable value
    +-- ServiceError             a service call failed (the server said so, or the connection died)
    +-- ShutdownError            the node is shut down (rospy maps this to ROSInterruptException)
    +-- TimeoutError_            a wait ran out of time
    +-- PackageError             package.xml / workspace / launch-time package lookup problems
    +-- LaunchError              a launch file is malformed or refers to something missing
    +-- BagError                 a bag file is malformed or cannot be written
    +-- ActionException          a class given as an action is not one (actionlib's ActionException)
    +-- (beside their code)      TurtleError, SpawnError, PlanError, ConversionError (also ValueErrors),
                                 OpError, HttpError, RvizConfigError, CfgError, ...

tests/test_rulebook.py walks every module and checks that each exception class is in this tree.

The rospy facade maps these onto rospy.ROSException, ROSInterruptException, ServiceException, ...
"""

from __future__ import annotations


class NinjemysError(Exception):
    """Root of every error ninjemys raises on purpose."""


class DefinitionError(NinjemysError):
    """A message/service/action definition is malformed.

    The message reads ``path:line: what is wrong`` so editors and terminals can jump to it.
    """

    def __init__(self, message: str, path: str | None = None, line: int | None = None) -> None:
        self.path = path
        self.line = line
        self.reason = message
        where = ""
        if path is not None:
            where = f"{path}:{line}: " if line is not None else f"{path}: "
        super().__init__(f"{where}{message}")


class TypeNotFoundError(NinjemysError):
    """An interface type or package is unknown; the message names what was searched."""


class SerializationError(NinjemysError):
    """A field value cannot be serialized (wrong Python type, out of range)."""


class DeserializationError(NinjemysError):
    """Received bytes do not decode as the expected message type."""


class NameError_(NinjemysError):
    """A ROS graph name is invalid."""


class ProtocolError(NinjemysError):
    """A peer violated the TCPROS or XML-RPC protocol."""


class MasterError(NinjemysError):
    """The master answered a call with a failure or error code."""


class MasterUnreachable(MasterError):
    """The master could not be contacted at all; ``cause`` is the socket's error when there was one
    (rospy lets it through as it is: ``ConnectionRefusedError`` when no master runs)."""

    def __init__(self, message: str, cause: OSError | None = None) -> None:
        super().__init__(message)
        self.cause = cause


class ParameterError(NinjemysError):
    """A parameter is not set or its value cannot be used."""


class ServiceError(NinjemysError):
    """A service call failed."""


class ShutdownError(NinjemysError):
    """The node has been shut down."""


class TimeoutError_(NinjemysError):
    """A wait ran out of time."""


class PackageError(NinjemysError):
    """A package, package.xml or workspace problem."""


class LaunchError(NinjemysError):
    """A launch file is malformed or refers to something missing."""


class BagError(NinjemysError):
    """A bag file is malformed or cannot be written."""


class ActionException(NinjemysError):
    """A class given to an action server or client is not an action (no action_goal/result/feedback)."""
