"""The checks: a named function, a composite of checks, event frequency, message stamp delays, the
heartbeat, and the topic diagnostics built from them."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import rospy

from ._status import DiagnosticStatusWrapper


class DiagnosticTask:
    """A named check; :meth:`run` fills the status it is given and returns it."""

    def __init__(self, name: str) -> None:
        self.name = name

    def getName(self) -> str:  # noqa: N802 - ROS 1's name
        return self.name

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        return stat


class FunctionDiagnosticTask(DiagnosticTask):
    """A check made of a function ``fn(stat) -> stat``."""

    def __init__(self, name: str, fn: Callable[[DiagnosticStatusWrapper], Any]) -> None:
        super().__init__(name)
        self.fn = fn

    def run(self, stat: DiagnosticStatusWrapper) -> Any:
        return self.fn(stat)


class CompositeDiagnosticTask(DiagnosticTask):
    """Several checks reported as one status: the worst level, the messages merged
    (:meth:`DiagnosticStatusWrapper.mergeSummary`), every check's values."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.tasks: list[DiagnosticTask] = []

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        combined = DiagnosticStatusWrapper()
        original = DiagnosticStatusWrapper()
        original.summary(stat)
        for task in self.tasks:
            stat.summary(original)  # each check starts from the summary the composite was given
            stat = task.run(stat)
            combined.mergeSummary(stat)
        stat.summary(combined)
        return stat

    def addTask(self, t: DiagnosticTask) -> None:  # noqa: N802
        self.tasks.append(t)


class FrequencyStatusParam:
    """Bounds for :class:`FrequencyStatus`: ``freq_bound`` is a dict with ``'min'`` and optionally
    ``'max'`` (a dict, so a node may change the bounds later), accepted within ``tolerance``; the rate
    is measured over the last ``window_size`` reports."""

    def __init__(self, freq_bound: dict[str, float], tolerance: float = 0.1, window_size: int = 5) -> None:
        self.freq_bound = freq_bound
        self.tolerance = tolerance
        self.window_size = window_size


class FrequencyStatus(DiagnosticTask):
    """Counts :meth:`tick` calls; each report gives the rate over the last ``window_size`` reports:
    ERROR with no events, WARN outside the bounds, else OK "Desired frequency met"."""

    def __init__(self, params: FrequencyStatusParam, name: str = "FrequencyStatus") -> None:
        super().__init__(name)
        self.params = params
        self.lock = threading.Lock()
        self.clear()

    def clear(self) -> None:
        """Forget every event: the window starts now."""
        with self.lock:
            self.count = 0
            now = rospy.Time.now()
            self.times = [now] * self.params.window_size
            self.seq_nums = [0] * self.params.window_size
            self.hist_indx = 0

    def tick(self) -> None:
        """One event."""
        with self.lock:
            self.count += 1

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        bound, tolerance = self.params.freq_bound, self.params.tolerance
        with self.lock:
            now = rospy.Time.now()
            events = self.count - self.seq_nums[self.hist_indx]
            window = (now - self.times[self.hist_indx]).to_sec()
            freq = (
                events / window
            )  # a report in the same instant as the window's start divides by zero, as in ROS 1
            self.seq_nums[self.hist_indx] = self.count
            self.times[self.hist_indx] = now
            self.hist_indx = (self.hist_indx + 1) % self.params.window_size
            if events == 0:
                stat.summary(2, "No events recorded.")
            elif freq < bound["min"] * (1 - tolerance):
                stat.summary(1, "Frequency too low.")
            elif "max" in bound and freq > bound["max"] * (1 + tolerance):
                stat.summary(1, "Frequency too high.")
            else:
                stat.summary(0, "Desired frequency met")
            stat.add("Events in window", "%d" % events)
            stat.add("Events since startup", "%d" % self.count)
            stat.add("Duration of window (s)", "%f" % window)
            stat.add("Actual frequency (Hz)", "%f" % freq)
            if "max" in bound and bound["min"] == bound["max"]:
                stat.add("Target frequency (Hz)", "%f" % bound["min"])
            if bound["min"] > 0:
                stat.add("Minimum acceptable frequency (Hz)", "%f" % (bound["min"] * (1 - tolerance)))
            if "max" in bound:
                stat.add("Maximum acceptable frequency (Hz)", "%f" % (bound["max"] * (1 + tolerance)))
        return stat


class TimeStampStatusParam:
    """Accepted delays (seconds, now minus the stamp) for :class:`TimeStampStatus`."""

    def __init__(self, min_acceptable: float = -1, max_acceptable: float = 5) -> None:
        self.min_acceptable = min_acceptable
        self.max_acceptable = max_acceptable


class TimeStampStatus(DiagnosticTask):
    """Watches the delay of the stamps given to :meth:`tick` since the last report: ERROR for stamps
    too far in the future or past or a zero stamp, WARN with no data, and running tallies."""

    def __init__(self, params: TimeStampStatusParam | None = None, name: str = "Timestamp Status") -> None:
        super().__init__(name)
        self.params = params if params is not None else TimeStampStatusParam()
        self.lock = threading.Lock()
        self.early_count = self.late_count = self.zero_count = 0
        self.zero_seen = False
        self.max_delta = self.min_delta = 0.0
        self.deltas_valid = False

    def tick(self, stamp: Any) -> None:
        """One stamp (a rospy Time or float seconds)."""
        seconds = stamp if isinstance(stamp, float) else stamp.to_sec()
        with self.lock:
            if seconds == 0:
                self.zero_seen = True
                return
            delta = rospy.Time.now().to_sec() - seconds
            if not self.deltas_valid or delta > self.max_delta:
                self.max_delta = delta
            if not self.deltas_valid or delta < self.min_delta:
                self.min_delta = delta
            self.deltas_valid = True

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        with self.lock:
            stat.summary(0, "Timestamps are reasonable.")
            if not self.deltas_valid:
                stat.summary(1, "No data since last update.")
            else:
                if self.min_delta < self.params.min_acceptable:
                    stat.summary(2, "Timestamps too far in future seen.")
                    self.early_count += 1
                if self.max_delta > self.params.max_acceptable:
                    stat.summary(2, "Timestamps too far in past seen.")
                    self.late_count += 1
                if self.zero_seen:
                    stat.summary(2, "Zero timestamp seen.")
                    self.zero_count += 1
            stat.add("Earliest timestamp delay:", "%f" % self.min_delta)
            stat.add("Latest timestamp delay:", "%f" % self.max_delta)
            stat.add("Earliest acceptable timestamp delay:", "%f" % self.params.min_acceptable)
            stat.add("Latest acceptable timestamp delay:", "%f" % self.params.max_acceptable)
            stat.add("Late diagnostic update count:", "%i" % self.late_count)
            stat.add("Early diagnostic update count:", "%i" % self.early_count)
            stat.add("Zero seen diagnostic update count:", "%i" % self.zero_count)
            self.deltas_valid = False
            self.min_delta = self.max_delta = 0.0
            self.zero_seen = False
        return stat


class Heartbeat(DiagnosticTask):
    """Always OK "Alive": the node is running."""

    def __init__(self) -> None:
        super().__init__("Heartbeat")

    def run(self, stat: DiagnosticStatusWrapper) -> DiagnosticStatusWrapper:
        stat.summary(0, "Alive")
        return stat


class HeaderlessTopicDiagnostic(CompositeDiagnosticTask):
    """``"<topic> topic status"``: a FrequencyStatus added to the updater ``diag``.

    As in ROS 1's Python module (Noetic's, Debian's 1.11), :meth:`tick` restarts the frequency window
    (it calls ``clear``, where the C++ class counts an event); kept so the reports are the same."""

    def __init__(self, name: str, diag: Any, freq: FrequencyStatusParam) -> None:
        super().__init__(name + " topic status")
        self.diag = diag
        self.freq = FrequencyStatus(freq)
        self.addTask(self.freq)
        self.diag.add(self)

    def tick(self) -> None:
        self.freq.clear()


class TopicDiagnostic(HeaderlessTopicDiagnostic):
    """A topic's frequency and its messages' stamp delays."""

    def __init__(self, name: str, diag: Any, freq: FrequencyStatusParam, stamp: TimeStampStatusParam) -> None:
        super().__init__(name, diag, freq)
        self.stamp = TimeStampStatus(stamp)
        self.addTask(self.stamp)

    def tick(self, stamp: Any) -> None:  # type: ignore[override]
        self.stamp.tick(stamp)
        super().tick()


class DiagnosedPublisher(TopicDiagnostic):
    """A publisher whose :meth:`publish` also ticks the topic diagnostic with the message's stamp."""

    def __init__(self, pub: Any, diag: Any, freq: FrequencyStatusParam, stamp: TimeStampStatusParam) -> None:
        super().__init__(pub.name, diag, freq, stamp)
        self.publisher = pub

    def publish(self, message: Any) -> None:
        self.tick(message.header.stamp)
        self.publisher.publish(message)
