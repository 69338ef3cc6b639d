"""``<test pkg="rostest" type="hztest">``: a topic is published at the expected rate.

Course and driver packages check a node's output rate with rostest's stock hztest node and its
private parameters: ``~topic``, ``~hz``, ``~hzerror``, ``~test_duration``, ``~wait_time`` (20 s),
``~check_intervals`` and ``~wall_clock``. It waits for the first message, measures over
``test_duration`` and passes when the average rate is within ``hz ± hzerror`` (``hz: 0``: no
message may arrive). It reports through ``rostest.rosrun``, so rostest reads its JUnit XML.
"""

from __future__ import annotations

import sys
import threading
import time
import unittest

import rospy
import rostest


class HzTest(unittest.TestCase):
    """The single test case hztest runs."""

    def setUp(self) -> None:
        self.lock = threading.Lock()
        self.received = False
        self.count = 0
        self.first = -1.0
        self.last = -1.0
        self.errors: list[str] = []
        self.min_interval = self.max_interval = 0.0
        self.check_intervals = False
        self.wall_clock = False

    def test_hz(self) -> None:
        try:
            hz = float(rospy.get_param("~hz"))
            duration = float(rospy.get_param("~test_duration"))
            topic = str(rospy.get_param("~topic"))
            hzerror = float(rospy.get_param("~hzerror")) if hz > 0 else 0.0
        except KeyError as exc:
            self.fail(f"hztest not initialized properly. Parameter [{exc.args[0]}] not set.")
        wait_time = float(rospy.get_param("~wait_time", 20.0))
        self.check_intervals = bool(rospy.get_param("~check_intervals", False))
        self.wall_clock = bool(rospy.get_param("~wall_clock", False))
        self.assertTrue(hz >= 0.0 and hzerror >= 0.0 and duration > 0.0 and topic, "bad parameters")
        low, high = (hz - hzerror, hz + hzerror) if hz > 0 else (0.0, 0.0)
        if hz > 0:
            self.min_interval = 1.0 / high
            self.max_interval = 1.0 / low if low > 0 else 0.0
        sub = rospy.Subscriber(topic, rospy.AnyMsg, self._heard)
        print("Waiting for messages", flush=True)
        deadline = time.time() + wait_time
        while not self.received and time.time() < deadline:
            time.sleep(0.1)
        if hz > 0:
            self.assertTrue(self.received, "no messages before timeout")
        else:
            self.assertFalse(self.received, "message received")
        print("Starting rate measurement", flush=True)
        clock = time.time if self.wall_clock else rospy.get_time
        end = clock() + duration
        while clock() < end:
            time.sleep(0.1) if self.wall_clock else rospy.sleep(0.1)
        print("Done waiting, validating results", flush=True)
        sub.unregister()
        if hz == 0:
            self.assertEqual(0, self.count)
            return
        self.assertTrue(self.count > 0, "no messages received")
        self.assertTrue(not self.errors, "\n".join(self.errors))
        span = self.last - self.first
        self.assertTrue(span > 0.0, "only one message received")
        rate = (self.count - 1) / span
        self.assertTrue(rate >= low, f"average rate ({rate:.3f}Hz) exceeded minimum ({low:.3f}Hz)")
        self.assertTrue(rate <= high, f"average rate ({rate:.3f}Hz) exceeded maximum ({high:.3f}Hz)")

    def _heard(self, _msg: object) -> None:
        self.received = True
        now = time.time() if self.wall_clock else rospy.get_rostime().to_sec()
        if now == 0.0:
            return  # sim time before the first /clock
        with self.lock:
            previous = self.last
            if self.first <= 0.0 or self.first > now:
                self.first, self.count, previous = now, 1, 0.0
            else:
                self.count += 1
            self.last = now
            if self.check_intervals and previous > 0:
                interval = now - previous
                if interval < self.min_interval:
                    self.errors.append(
                        f"min_interval exceeded: {interval} [actual] vs. {self.min_interval} [min]"
                    )
                elif self.max_interval > 0.0 and interval > self.max_interval:
                    self.errors.append(
                        f"max_interval exceeded: {interval} [actual] vs. {self.max_interval} [max]"
                    )


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``rosrun rostest hztest`` / ``<test pkg="rostest" type="hztest">``."""
    args = sys.argv if argv is None else [sys.argv[0], *argv]
    rospy.init_node("hztest", argv=args)
    time.sleep(0.75)  # as ROS 1's: let publishers that start with the test come up
    try:
        rostest.rosrun("rostest", "hztest", HzTest, args)
    except KeyboardInterrupt:
        pass
