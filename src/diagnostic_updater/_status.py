"""``DiagnosticStatusWrapper``: a DiagnosticStatus with the helpers check functions use."""

from __future__ import annotations

from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

OK = DiagnosticStatus.OK
WARN = DiagnosticStatus.WARN
ERROR = DiagnosticStatus.ERROR
STALE = DiagnosticStatus.STALE


class DiagnosticStatusWrapper(DiagnosticStatus):  # type: ignore[misc]
    """A DiagnosticStatus message (it is published as one) with summary and key-value helpers."""

    def summary(self, *args: Any) -> None:
        """``summary(status)`` copies another status' level and message; ``summary(level, text)`` sets them."""
        if len(args) == 1:
            self.level, self.message = args[0].level, args[0].message
        elif len(args) == 2:
            self.level, self.message = args[0], str(args[1])

    def clearSummary(self) -> None:  # noqa: N802 - ROS 1's name
        """Level OK and no message."""
        self.summary(0, "")

    def mergeSummary(self, *args: Any) -> None:  # noqa: N802
        """Fold another level and message into this one: the worse level wins; messages of the same
        kind (both OK, or both not OK) are joined with ``"; "``, a worse one replaces an OK one."""
        if len(args) == 1:
            level, message = args[0].level, args[0].message
        else:
            level, message = args[0], args[1]
        if (level > 0) == (self.level > 0):
            self.message = f"{self.message}; {message}" if self.message else message
        elif level > self.level:
            self.message = message
        self.level = max(self.level, level)

    def add(self, key: str, val: Any) -> None:
        """Append a key-value pair, the value as ``str()`` makes it."""
        self.values.append(KeyValue(key, str(val)))
