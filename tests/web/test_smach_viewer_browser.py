"""smach_viewer's page in headless Chromium: ``rosrun smach_viewer smach_viewer.py`` draws a running
state machine (nested container, states, transitions, outcomes) from the introspection topics and
follows the active state live, all through the gateway."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from ninjemys.testing import free_port, kill_tree, ninjemys_bin, run_master

pytestmark = pytest.mark.browser

MACHINE = r"""
import sys, threading, rospy, smach, smach_ros

rospy.init_node("viewed")
gates = {name: threading.Event() for name in ("ONE", "TWO")}

class Gate(smach.State):
    def __init__(self, name):
        smach.State.__init__(self, outcomes=["open", "preempted"])
        self.name = name
    def execute(self, ud):
        while not gates[self.name].wait(0.05):
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
        return "open"

sm = smach.StateMachine(outcomes=["finished", "preempted"])
inner = smach.StateMachine(outcomes=["inner_done", "preempted"])
with inner:
    smach.StateMachine.add("TWO", Gate("TWO"), transitions={"open": "inner_done"})
with sm:
    smach.StateMachine.add("ONE", Gate("ONE"), transitions={"open": "INNER"})
    smach.StateMachine.add("INNER", inner, transitions={"inner_done": "finished"})
sis = smach_ros.IntrospectionServer("viewed_sis", sm, "/SM_ROOT")
sis.start()
smach_ros.set_preempt_handler(sm)

def control():
    for line in sys.stdin:
        gates[line.strip()].set()
threading.Thread(target=control, daemon=True).start()
print("outcome", sm.execute(), flush=True)
"""


def test_viewer_draws_the_machine_and_follows_the_active_state(browser_page: Any, tmp_path: Path) -> None:
    env = dict(os.environ, ROS_HOME=str(tmp_path), ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1")
    env.pop("ROS_NAMESPACE", None)
    with run_master(env=env) as uri:
        env["ROS_MASTER_URI"] = uri
        (tmp_path / "machine.py").write_text(MACHINE)
        machine = subprocess.Popen(
            [sys.executable, str(tmp_path / "machine.py")],
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        viewer = subprocess.Popen(
            [
                ninjemys_bin("rosrun"),
                "smach_viewer",
                "smach_viewer.py",
                "--no-browser",
                "--port",
                str(free_port()),
            ],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert viewer.stdout is not None
            line = viewer.stdout.readline().strip()
            assert line.startswith("smach_viewer: http://"), line + (
                viewer.stderr.read() if viewer.stderr else ""
            )
            page = browser_page
            page.goto(line.split(": ", 1)[1])
            page.wait_for_function("window.smachViewer && window.smachViewer.ready", timeout=30000)
            page.wait_for_function(
                "(() => { const d = window.smachViewer.drawn; return d && d.containers.length === 2 && d.active.includes('/SM_ROOT/ONE'); })()",
                timeout=30000,
            )
            drawn = page.evaluate("window.smachViewer.drawn")
            assert drawn["server"] == "/viewed_sis"
            root = next(c for c in drawn["containers"] if c["path"] == "/SM_ROOT")
            assert sorted(root["children"]) == ["INNER", "ONE"]
            assert sorted(root["outcomes"]) == ["finished", "preempted"]
            assert ["open", "ONE", "INNER"] in root["edges"] and ["inner_done", "INNER", "finished"] in root[
                "edges"
            ]
            # the drawing itself: the nested container's box holds its state, the active state is marked
            assert (
                page.locator(
                    "g.sv-container[data-path='/SM_ROOT/INNER'] g.sv-state[data-state='TWO']"
                ).count()
                == 1
            )
            assert page.locator("g.sv-state.active[data-state='ONE']").count() == 1
            assert (
                page.locator("path.sv-edge[data-outcome='open'][data-from='ONE'][data-to='INNER']").count()
                == 1
            )
            assert machine.stdin is not None
            machine.stdin.write("ONE\n")
            machine.stdin.flush()
            page.wait_for_function(
                "window.smachViewer.drawn.active.includes('/SM_ROOT/INNER/TWO')", timeout=20000
            )
            assert page.locator("g.sv-state.active[data-state='ONE']").count() == 0
            assert page.locator("g.sv-container.active[data-path='/SM_ROOT/INNER']").count() == 1
            machine.stdin.write("TWO\n")
            machine.stdin.flush()
            out, _ = machine.communicate(timeout=30)
            assert "outcome finished" in out.splitlines()
        finally:
            kill_tree(viewer)
            kill_tree(machine)
