"""ROS 1's ``diagnostic_updater`` (Python): a node's self-reports on ``/diagnostics``.

Drivers and course nodes register check functions with an :class:`Updater` (``updater.add("Battery",
check)``), call ``updater.update()`` in their loop, and get one ``diagnostic_msgs/DiagnosticArray``
per ``~diagnostic_period`` (1 s) with a status per check, named ``"<node>: <check>"``;
:class:`FrequencyStatus`, :class:`TimeStampStatus` and the topic diagnostics watch publishing rates
and stamps. Behaviour and texts are Noetic's (Debian's python3-diagnostic-updater is the reference
in ``tests/diagnostic_updater``).
"""

from ._status import ERROR, OK, STALE, WARN, DiagnosticStatusWrapper
from ._tasks import (
    CompositeDiagnosticTask,
    DiagnosedPublisher,
    DiagnosticTask,
    FrequencyStatus,
    FrequencyStatusParam,
    FunctionDiagnosticTask,
    HeaderlessTopicDiagnostic,
    Heartbeat,
    TimeStampStatus,
    TimeStampStatusParam,
    TopicDiagnostic,
)
from ._updater import DiagnosticTaskVector, Updater

__all__ = [
    "ERROR",
    "OK",
    "STALE",
    "WARN",
    "CompositeDiagnosticTask",
    "DiagnosedPublisher",
    "DiagnosticStatusWrapper",
    "DiagnosticTask",
    "DiagnosticTaskVector",
    "FrequencyStatus",
    "FrequencyStatusParam",
    "FunctionDiagnosticTask",
    "HeaderlessTopicDiagnostic",
    "Heartbeat",
    "TimeStampStatus",
    "TimeStampStatusParam",
    "TopicDiagnostic",
    "Updater",
]
