"""The task list and the :class:`Updater` that runs it and publishes ``/diagnostics``."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import rospy
from diagnostic_msgs.msg import DiagnosticArray

from ._status import DiagnosticStatusWrapper

_NO_HWID = (
    "diagnostic_updater: No HW_ID was set. This is probably a bug. Please report it. For devices that do "
    "not have a HW_ID, set this value to 'none'. This warning only occurs once all diagnostics are OK so "
    "it is okay to wait until the device is open before calling setHardwareID."
)


class _NamedTask:
    """A check function under the name its status is published with."""

    def __init__(self, name: str, fn: Callable[[DiagnosticStatusWrapper], Any]) -> None:
        self.name = name
        self.fn = fn

    def run(self, stat: DiagnosticStatusWrapper) -> Any:
        stat.name = self.name
        return self.fn(stat)


class DiagnosticTaskVector:
    """The registered checks: ``add(task)`` or ``add(name, function)``, ``removeByName(name)``."""

    DiagnosticTaskInternal = _NamedTask

    def __init__(self) -> None:
        self.tasks: list[_NamedTask] = []
        self.lock = threading.Lock()

    def addedTaskCallback(self, task: _NamedTask) -> None:  # noqa: N802 - ROS 1's name
        """Called for each new task (the Updater announces it)."""

    def add(self, *args: Any) -> None:
        task = _NamedTask(args[0].getName(), args[0].run) if len(args) == 1 else _NamedTask(args[0], args[1])
        with self.lock:
            self.tasks.append(task)
            self.addedTaskCallback(task)

    def removeByName(self, name: str) -> bool:  # noqa: N802
        """Remove the first task of that name; whether one was there."""
        with self.lock:
            for index, task in enumerate(self.tasks):
                if task.name == name:
                    del self.tasks[index]
                    return True
        return False


class Updater(DiagnosticTaskVector):
    """Runs every check once per ``~diagnostic_period`` seconds (read every 0.25 s; default 1) when
    :meth:`update` is called, and publishes the statuses on ``/diagnostics``."""

    def __init__(self) -> None:
        super().__init__()
        self.publisher = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=10)
        self.last_time = rospy.Time.now()
        self.last_time_period_checked = self.last_time
        self.period: float = 1
        self.verbose = False
        self.hwid = ""
        self.warn_nohwid_done = False

    def update(self) -> None:
        """Publish if the period has passed since the last publication."""
        self._check_diagnostic_period()
        if rospy.Time.now() >= self.last_time + rospy.Duration(self.period):
            self.force_update()

    def force_update(self) -> None:
        """Run every check and publish now. A check that sets nothing reports ERROR "No message was set"."""
        self.last_time = rospy.Time.now()
        warn_nohwid = len(self.hwid) == 0
        statuses = []
        with self.lock:
            for task in self.tasks:
                status = DiagnosticStatusWrapper()
                status.name = task.name
                status.level = 2
                status.message = "No message was set"
                status.hardware_id = self.hwid
                task.run(status)  # ROS 1 publishes the status it handed over, whatever run returns
                statuses.append(status)
                if status.level:
                    warn_nohwid = False
                if self.verbose and status.level:
                    rospy.logwarn(
                        "Non-zero diagnostic status. Name: '%s', status %i: '%s'"
                        % (status.name, status.level, status.message)
                    )
        if warn_nohwid and not self.warn_nohwid_done:
            rospy.logwarn(_NO_HWID)
            self.warn_nohwid_done = True
        self.publish(statuses)

    def broadcast(self, lvl: int, msg: str) -> None:
        """Publish one level and message for every check, without running them."""
        statuses = []
        for task in self.tasks:
            status = DiagnosticStatusWrapper()
            status.name = task.name
            status.summary(lvl, msg)
            statuses.append(status)
        self.publish(statuses)

    def setHardwareID(self, hwid: str) -> None:  # noqa: N802
        self.hwid = hwid

    def _check_diagnostic_period(self) -> None:
        now = rospy.Time.now()
        if now >= self.last_time_period_checked + rospy.Duration(0.25):
            self.period = rospy.get_param_cached("~diagnostic_period", 1)
            self.last_time_period_checked = now

    def publish(self, msg: Any) -> None:
        """Publish statuses (one or a list), each renamed ``"<node name without the slash>: <name>"``."""
        statuses = msg if isinstance(msg, list) else [msg]
        for status in statuses:
            status.name = rospy.get_name()[1:] + ": " + status.name
        array = DiagnosticArray()
        array.status = statuses
        array.header.stamp = rospy.Time.now()
        self.publisher.publish(array)

    def addedTaskCallback(self, task: _NamedTask) -> None:  # noqa: N802
        """A new check is announced at once as OK "Node starting up"."""
        status = DiagnosticStatusWrapper()
        status.name = task.name
        status.summary(0, "Node starting up")
        self.publish(status)
