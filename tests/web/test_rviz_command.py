"""The ``rviz`` command (and ``rosrun rviz rviz``), and .rviz files read and written in rviz's layout."""

from __future__ import annotations

import os
import re
import signal
import subprocess
from pathlib import Path
from typing import Any

import pytest
import yaml

from ninjemys.master.core import MasterThread
from ninjemys.packages.discovery import PackageIndex
from ninjemys.testing import ninjemys_bin, wait_until
from ninjemys.web import rvizconfig

NAV_RVIZ = PackageIndex.from_environment().find("puzzlebot_navigation").path / "rviz" / "navigation.rviz"


def test_groups_are_flattened_and_unknown_classes_named() -> None:
    text = """
Visualization Manager:
  Displays:
    - Class: rviz/Group
      Name: Navigation
      Displays:
        - {Class: rviz/Path, Name: Plan, Topic: /plan, Color: "25; 255; 0", Enabled: true, Line Style: Lines}
        - {Class: rviz/Camera, Name: Cam, Image Topic: /cam}
    - {Class: rviz/Marker, Name: M, Marker Topic: /viz, Enabled: false}
  Global Options: {Fixed Frame: odom}
  Tools:
    - {Class: rviz/SetGoal, Topic: /goal}
  Views:
    Current: {Class: rviz/TopDownOrtho, Scale: 30, X: 2, Y: -1}
"""
    config = rvizconfig.parse(text, "x.rviz")
    assert config.fixed_frame == "odom"
    assert [(d["cls"], d["name"], d["topic"], d["enabled"]) for d in config.displays] == [
        ("rviz/Path", "Plan", "/plan", True),
        ("rviz/Marker", "M", "/viz", False),
    ]
    assert config.displays[0]["options"] == {"Line Style": "Lines"}
    assert config.unsupported == [{"cls": "rviz/Camera", "name": "Cam", "topic": ""}]
    assert config.tools["rviz/SetGoal"] == "/goal"
    assert config.view == {"mode": "top", "scale": 30, "x": 2, "y": -1}
    # written back: our displays updated, the camera kept, unknown keys kept
    page = {"fixedFrame": "map", "displays": [dict(config.displays[0], topic="/plan2")]}
    doc = yaml.safe_load(rvizconfig.dump(page, config))
    displays = doc["Visualization Manager"]["Displays"]
    assert [d["Class"] for d in displays] == ["rviz/Path", "rviz/Camera"]
    assert displays[0]["Topic"] == "/plan2" and displays[0]["Line Style"] == "Lines"
    assert doc["Visualization Manager"]["Views"]["Current"]["Scale"] == 30
    assert doc["Visualization Manager"]["Global Options"]["Fixed Frame"] == "map"


def test_parse_errors_name_the_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.rviz"
    bad.write_text("Visualization Manager:\n  Displays:\n    - Class: rviz/Grid\n  - oops: [\n")
    with pytest.raises(rvizconfig.RvizConfigError, match=rf"^{re.escape(str(bad))}:4: "):
        rvizconfig.load(bad)
    with pytest.raises(
        rvizconfig.RvizConfigError, match=r"^y.rviz: Displays\[0\]: a display must be a mapping"
    ):
        rvizconfig.parse("Visualization Manager:\n  Displays: [3]\n", "y.rviz")
    with pytest.raises(rvizconfig.RvizConfigError, match="No such file"):
        rvizconfig.load(tmp_path / "missing.rviz")


@pytest.mark.browser
@pytest.mark.parametrize("how", ["rviz", "rosrun"])
def test_rviz_d_opens_the_navigation_displays(how: str, tmp_path: Path, browser_page: Any) -> None:
    with MasterThread() as uri:
        cmd = [ninjemys_bin("rviz")] if how == "rviz" else [ninjemys_bin("rosrun"), "rviz", "rviz"]
        proc = subprocess.Popen(
            [*cmd, "-d", str(NAV_RVIZ), "--no-browser", "--port", "0"],
            env=dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=str(tmp_path), PYTHONUNBUFFERED="1"),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        try:
            line = proc.stdout.readline()
            match = re.match(r"rviz: (http://localhost:\d+/rviz)$", line.strip())
            assert match, line
            page = browser_page
            page.goto(match.group(1))
            page.wait_for_function("window.rviz && window.rviz.ready", timeout=20000)
            names = page.locator(".rv-display").evaluate_all("els => els.map(e => e.dataset.name)")
            assert names == [
                "Grid",
                "Map",
                "Global Costmap",
                "Local Costmap",
                "RobotModel",
                "TF",
                "LaserScan",
                "Particles",
                "AMCL Pose",
                "Global Plan",
                "Local Plan",
                "Goal",
                "Camera",
            ]
            assert page.locator("#rv-viewmode").input_value() == "top"
            # nobody publishes yet: each topic display says so, none fails
            wait_until(
                lambda: (
                    "No messages received on /scan"
                    in page.locator('.rv-display[data-name="LaserScan"] .rv-status').inner_text()
                ),
                what="the scan display's status",
            )
        finally:
            proc.send_signal(signal.SIGINT)
            assert proc.wait(20) == 0


def test_saving_takes_json_only_and_writes_the_started_file(tmp_path: Path) -> None:
    import json
    import urllib.error
    import urllib.request

    from ninjemys.web.rviz import Rviz

    config = tmp_path / "mine.rviz"
    config.write_text("Visualization Manager:\n  Displays: []\n")
    with MasterThread() as uri:
        rviz = Rviz(uri, str(config), update_period=0.2)
        try:
            base = rviz.start().removesuffix("rviz")
            body = json.dumps(
                {"fixedFrame": "odom", "displays": [], "path": str(tmp_path / "other.rviz")}
            ).encode()
            plain = urllib.request.Request(base + "api/rviz/config", body, {"Content-Type": "text/plain"})
            with pytest.raises(urllib.error.HTTPError) as err:
                urllib.request.urlopen(plain, timeout=10)
            assert err.value.code == 415
            ok = urllib.request.Request(base + "api/rviz/config", body, {"Content-Type": "application/json"})
            with urllib.request.urlopen(ok, timeout=10) as resp:
                assert json.load(resp)["path"] == str(config)
            assert not (tmp_path / "other.rviz").exists()
            assert (
                yaml.safe_load(config.read_text())["Visualization Manager"]["Global Options"]["Fixed Frame"]
                == "odom"
            )
        finally:
            rviz.stop()
