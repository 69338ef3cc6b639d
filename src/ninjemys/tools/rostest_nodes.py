"""rostest's other stock test nodes: ``publishtest``, ``paramtest`` and ``advertisetest``.

Packages put them in their ``.test`` files next to ``hztest`` (:mod:`ninjemys.tools.hztest`), with
the same package and type names and the same private parameters as rostest 1.15:

* ``publishtest``: ``~topics``, a list of ``{name, timeout: 10, negative: false}``; passes when a
  message arrives on each topic within its timeout (``negative``: when none does);
* ``paramtest``: ``~param_name_target``, ``~param_value_expected``, ``~wait_time`` (20 s),
  ``~test_duration`` (5, checked to be positive); passes when the parameter appears within the wait
  (and equals the expected value, when one is given);
* ``advertisetest``: ``~topics`` and ``~services``, lists of ``{name, timeout: 10, type, negative}``;
  passes when each is advertised on the master within its timeout (``type``: with that type;
  ``negative``: never advertised). Names are compared as given, as rostest does: give them in full.

Timeouts count from the start of the test (ROS time for publishtest, wall time for the others, as
in rostest). Under ``/use_sim_time`` the tests first wait up to 10 s for ``/clock``. Each reports
through ``rostest.rosrun``, so the ``rostest`` command reads its JUnit XML.
"""

from __future__ import annotations

import sys
import time
import unittest
from collections.abc import Callable
from typing import Any

import rospy
import rosservice
import rostest

#: each checklist entry's defaults, as rostest's nodes have them
_TOPIC_DEFAULTS = {"timeout": 10, "negative": False}
_ADVERTISED_DEFAULTS = {"timeout": 10, "type": None, "negative": False}


def _entries(case: unittest.TestCase, key: str, defaults: dict[str, Any]) -> list[dict[str, Any]]:
    """The list parameter ``key`` with each entry's defaults filled in; an entry without a name fails
    the test case, naming the parameter."""
    entries = []
    for item in rospy.get_param(key, []) or []:
        if not isinstance(item, dict) or "name" not in item:
            case.fail(f"'name' field in rosparam is required but not specified ({rospy.resolve_name(key)}).")
        entries.append({**defaults, **item})
    return entries


def _wait_for_sim_clock(case: unittest.TestCase) -> None:
    """Under /use_sim_time, wait (wall clock, 10 s at most) for the first /clock."""
    if not rospy.get_param("/use_sim_time", False):
        return
    start = time.time()
    while not rospy.is_shutdown() and rospy.Time.now() == rospy.Time(0):
        rospy.logwarn_throttle(1, "/use_sim_time is specified and rostime is 0, /clock is published?")
        if time.time() - start > 10:
            case.fail("Timed out (10s) of /clock publication.")
        time.sleep(0.1)


class _Heard:
    """One topic of publishtest: whether a message came before the deadline."""

    def __init__(self, name: str, timeout: float, negative: bool) -> None:
        self.name, self.negative = name, negative
        self.deadline = rospy.Time.now() + rospy.Duration(timeout)
        self.heard = False
        self.sub = rospy.Subscriber(name, rospy.AnyMsg, self._on_message)

    def _on_message(self, _msg: object) -> None:
        self.heard = True

    def verdict(self) -> bool | None:
        """True when the topic behaved as asked, False when it did not, None while undecided."""
        if self.heard:
            return not self.negative
        if rospy.Time.now() > self.deadline:
            return self.negative
        return None


class PublishTest(unittest.TestCase):
    """``<test pkg="rostest" type="publishtest">``: messages come on every listed topic."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.topics = _entries(self, "~topics", _TOPIC_DEFAULTS)
        if not self.topics:
            self.fail("No topic is specified in rosparam.")

    def test_publish(self) -> None:
        """Test topics are published and messages come"""
        _wait_for_sim_clock(self)
        checks = []
        for topic in self.topics:
            print(
                f"Waiting [{topic['name']}] for [{int(topic['timeout'])}] seconds with negative [{topic['negative']}]"
            )
            checks.append(_Heard(topic["name"], float(topic["timeout"]), bool(topic["negative"])))
        pending = list(checks)
        while pending and not rospy.is_shutdown():
            for check in list(pending):
                verdict = check.verdict()
                if verdict is None:
                    continue
                pending.remove(check)
                if check.negative:
                    self.assertTrue(verdict, f"Topic [{check.name}] is published")
                else:
                    self.assertTrue(verdict, f"Topic [{check.name}] is not published")
            rospy.sleep(0.01)


class ParamTest(unittest.TestCase):
    """``<test pkg="rostest" type="paramtest">``: a parameter is set (to the expected value)."""

    def test_param(self) -> None:
        try:
            target = rospy.get_param("~param_name_target")
            expected = rospy.get_param("~param_value_expected", None)
            duration = float(rospy.get_param("~test_duration", 5))
            wait_time = float(rospy.get_param("~wait_time", 20))
        except KeyError as exc:
            self.fail(
                f"ParamTest not initialized properly. Parameter [{exc.args[0]}] not set. "
                f"Caller ID: [{rospy.get_caller_id()}] Resolved name: [{rospy.resolve_name(exc.args[0])}]"
            )
        print(f"Parameter: {target} Test Duration: {duration}")
        self.assertTrue(duration > 0.0, "bad parameter (test_duration)")
        self.assertTrue(len(target), "bad parameter (testattr_paramname_target)")
        print("Waiting for parameters")
        deadline = time.time() + wait_time
        found = None
        while found is None and time.time() < deadline:
            try:
                found = rospy.get_param(target)
            except KeyError:
                print(
                    f"Designated parameter [{target}] is not registered yet, will wait. "
                    f"Caller ID: [{rospy.get_caller_id()}] Resolved name: [{rospy.resolve_name(target)}]"
                )
            time.sleep(0.1)
        if expected:  # as rostest: an expected value that is false (0, "", empty) only asks for presence
            self.assertEqual(expected, found)
        else:
            self.assertIsNotNone(found)


class AdvertiseTest(unittest.TestCase):
    """``<test pkg="rostest" type="advertisetest">``: topics and services are (or are not) advertised."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.topics = {t["name"]: t for t in _entries(self, "~topics", _ADVERTISED_DEFAULTS)}
        self.services = {s["name"]: s for s in _entries(self, "~services", _ADVERTISED_DEFAULTS)}
        if not self.topics and not self.services:
            self.fail("No topic or service is specified in rosparam.")

    def setUp(self) -> None:
        _wait_for_sim_clock(self)
        self.start = time.time()

    def test_advertise_topics(self) -> None:
        """Test topics are advertised"""
        self._check("Topic", self.topics, lambda: dict(rospy.get_published_topics()).items())

    def test_advertise_services(self) -> None:
        """Test services are advertised"""

        def advertised() -> list[tuple[str, str | None]]:
            names = [n for n in rosservice.get_service_list() if n in self.services]
            return [(n, rosservice.get_service_type(n) if self.services[n]["type"] else None) for n in names]

        self._check("Service", self.services, advertised)

    def _check(self, kind: str, wanted: dict[str, dict[str, Any]], advertised: Callable[[], Any]) -> None:
        if not wanted:
            return
        pending = set(wanted)
        longest = max(float(w["timeout"]) for w in wanted.values())
        while pending and not rospy.is_shutdown():
            elapsed = time.time() - self.start
            if elapsed > longest:
                break
            for name, kind_of in advertised():
                if name not in pending:
                    continue
                pending.discard(name)
                entry = wanted[name]
                self.assertTrue(
                    elapsed < float(entry["timeout"]),
                    f"{kind} [{name}] is advertised only after its timeout [{entry['timeout']}] secs",
                )
                self.assertFalse(entry["negative"], f"{kind} [{name}] is advertised")
                if entry["type"] is not None:
                    self.assertEqual(kind_of, entry["type"], f"{kind} type of [{name}] is [{kind_of}]")
            time.sleep(0.05)
        for name in sorted(pending):
            self.assertTrue(wanted[name]["negative"], f"{kind} [{name}] is not advertised")


def _main(name: str, case: type[unittest.TestCase], argv: list[str] | None) -> None:
    args = sys.argv if argv is None else [sys.argv[0], *argv]
    rospy.init_node(name, argv=args)
    try:
        rostest.rosrun("rostest", name, case, args)
    except KeyboardInterrupt:
        pass


def publishtest_main(argv: list[str] | None = None) -> None:
    """``rosrun rostest publishtest`` / ``<test pkg="rostest" type="publishtest">``."""
    _main("publishtest", PublishTest, argv)


def paramtest_main(argv: list[str] | None = None) -> None:
    """``rosrun rostest paramtest`` / ``<test pkg="rostest" type="paramtest">``."""
    _main("paramtest", ParamTest, argv)


def advertisetest_main(argv: list[str] | None = None) -> None:
    """``rosrun rostest advertisetest`` / ``<test pkg="rostest" type="advertisetest">``."""
    _main("advertisetest", AdvertiseTest, argv)
