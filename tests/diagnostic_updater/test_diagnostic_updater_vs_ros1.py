"""``diagnostic_updater`` against Debian's python3-diagnostic-updater (ROS 1's Python module): the same
node script, run under Debian's rospy and ours against our master, publishes the same
``/diagnostics`` arrays (names, levels, messages, hardware ids, keys, and every value that does not
depend on the clock)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

_DEBIAN = Path("/usr/lib/python3/dist-packages/diagnostic_updater/_diagnostic_updater.py")

SCRIPT = r"""
import json, time
import rospy
import diagnostic_updater as du
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_msgs.msg import Header

got = []
rospy.init_node("diag_probe")
rospy.Subscriber("/diagnostics", DiagnosticArray, got.append)

def battery(stat):
    stat.summary(DiagnosticStatus.WARN, "Battery low")
    stat.add("Voltage", 11.2)
    stat.add("Cells", 3)
    return stat

def silent(stat):
    return stat

def fine(stat):
    stat.summary(0, "fine")
    stat.add("a", True)
    return stat

def bad(stat):
    stat.summary(2, "bad")
    return stat

def meh(stat):
    stat.mergeSummary(1, "meh")
    return stat

updater = du.Updater()
deadline = time.time() + 30
while updater.publisher.get_num_connections() < 1 and time.time() < deadline:
    time.sleep(0.05)  # the node's own subscriber connects to the new publisher
time.sleep(0.2)
updater.setHardwareID("probe-01")
updater.add("Battery", battery)
updater.add(du.FunctionDiagnosticTask("Motor", silent))
composite = du.CompositeDiagnosticTask("Drive")
for name, fn in (("left", fine), ("right", bad), ("mid", meh)):
    composite.addTask(du.FunctionDiagnosticTask(name, fn))
updater.add(composite)
updater.add(du.Heartbeat())
freq = du.HeaderlessTopicDiagnostic("scan", updater, du.FrequencyStatusParam({"min": 5, "max": 5}, 0.1, 10))
stamps = du.TimeStampStatus(du.TimeStampStatusParam(-1, 5))
updater.add(stamps)
time.sleep(0.3)
stamps.tick(0.0)
stamps.tick(rospy.Time.now() - rospy.Duration(30))
updater.force_update()
updater.broadcast(1, "shutting down")
print("removed", updater.removeByName("Battery"), updater.removeByName("nothing"))
updater.force_update()
w = du.DiagnosticStatusWrapper()
w.summary(0, "ok one"); w.mergeSummary(0, "ok two"); first = (w.level, w.message)
w.mergeSummary(2, "broken"); second = (w.level, w.message)
w.mergeSummary(1, "warned"); third = (w.level, w.message)
w.clearSummary()
print("merge", json.dumps([first, second, third, (w.level, w.message)]))
deadline = time.time() + 20
while len(got) < 9 and time.time() < deadline:
    time.sleep(0.05)
CLOCKED = ("Duration of window (s)", "Actual frequency (Hz)", "Earliest timestamp delay:", "Latest timestamp delay:")
for array in got:
    print("array", json.dumps([
        [s.name, s.level, s.message, s.hardware_id, [[kv.key, "*" if kv.key in CLOCKED else kv.value] for kv in s.values]]
        for s in array.status
    ]))
print("levels", du.OK, du.WARN, du.ERROR)
"""


def _run(python: str, master: str, tmp_path: Path) -> list[str]:
    env = dict(os.environ, ROS_MASTER_URI=master, ROS_HOME=str(tmp_path), ROS_HOSTNAME="localhost")
    done = subprocess.run([python, "-c", SCRIPT], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    return [
        line
        for line in done.stdout.splitlines()
        if line.split(" ", 1)[0] in ("array", "merge", "removed", "levels")
    ]


@pytest.mark.ros1
def test_same_diagnostics_as_debians_updater(tmp_path: Path) -> None:
    if not (testing.have_ros1() and _DEBIAN.is_file()):
        pytest.skip("Debian's python3-diagnostic-updater is not installed")
    with testing.run_master() as master:
        ours = _run(sys.executable, master, tmp_path)
    with testing.run_master() as master:
        theirs = _run(testing.ROS1_PYTHON, master, tmp_path)
    assert ours == theirs


def test_what_a_node_publishes(tmp_path: Path) -> None:
    with testing.run_master() as master:
        lines = _run(sys.executable, master, tmp_path)
    arrays = [json.loads(line.split(" ", 1)[1]) for line in lines if line.startswith("array ")]
    assert arrays[0] == [["diag_probe: Battery", 0, "Node starting up", "", []]]
    full = next(a for a in arrays if len(a) == 6 and a[0][2] == "Battery low")
    assert full[0] == [
        "diag_probe: Battery",
        1,
        "Battery low",
        "probe-01",
        [["Voltage", "11.2"], ["Cells", "3"]],
    ]
    assert full[1][:3] == ["diag_probe: Motor", 2, "No message was set"]
    # each part starts from the summary the composite got (ERROR "No message was set"), as in ROS 1
    assert full[2][:3] == ["diag_probe: Drive", 2, "bad; No message was set; meh"]
    assert full[3][:3] == ["diag_probe: Heartbeat", 0, "Alive"]
    assert full[4][:3] == ["diag_probe: scan topic status", 2, "No events recorded."]
    assert full[5][:3] == ["diag_probe: Timestamp Status", 2, "Zero timestamp seen."]
    assert ["Late diagnostic update count:", "1"] in full[5][4]
    assert (
        "merge " + json.dumps([[0, "ok one; ok two"], [2, "broken"], [2, "broken; warned"], [0, ""]]) in lines
    )
    assert "removed True False" in lines
