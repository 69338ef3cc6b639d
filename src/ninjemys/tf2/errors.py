"""tf2's exception classes, with the names and hierarchy of ROS 1's ``tf2_py`` (re-exported by tf2_ros).

They sit under :class:`ninjemys.errors.NinjemysError` so one ``except`` catches any ninjemys failure,
and under ``TransformException`` so ROS 1 code that catches tf2's base class keeps working. The
texts are tf2's own (``buffer_core.cpp`` / ``cache.cpp``): programs and tests match on them.
"""

from __future__ import annotations

from ninjemys.errors import NinjemysError


class TransformException(NinjemysError):
    """Base of every tf2 failure (``tf2.TransformException``)."""


class LookupException(TransformException):
    """A frame passed to a lookup does not exist (or the tree has a loop)."""


class ConnectivityException(TransformException):
    """The two frames exist but are not in the same tree."""


class ExtrapolationException(TransformException):
    """The requested time is outside the data in the buffer; the text says past or future and by how much."""


class InvalidArgumentException(TransformException):
    """An empty frame id, or one starting with '/'."""


class TimeoutException(TransformException):
    """A wait for a transform ran out of time."""


__all__ = [
    "TransformException",
    "LookupException",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "TimeoutException",
]
