"""Build point 6 (installing on the robot's computer) as checks on what ships: the Python versions the
docs promise are the ones pip enforces, pyserial comes with ninjemys while pyrealsense2 (no aarch64
wheel) stays optional, and the documented udev rules give the names the hardware launch file uses,
the same rule as ``rosrun rplidar_ros create_udev_rules.sh`` writes."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from ninjemys.drivers.udev_rules import RULE

ROOT = Path(__file__).resolve().parents[2]
DOCS = (ROOT / "docs/drivers.md").read_text()
RULE_FIELD = re.compile(r'([A-Z]+(?:\{\w+\})?)(==|:=|\+=)"([^"]*)"')


def _project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_the_documented_python_versions_are_the_ones_pip_enforces() -> None:
    assert _project()["requires-python"] == ">=3.11"
    assert "**Which Pythons work: CPython 3.11, 3.12 and 3.13.**" in DOCS
    assert 'requires-python = ">=3.11"' in DOCS


def test_pyserial_is_a_dependency_and_pyrealsense2_only_an_extra() -> None:
    project = _project()
    names = [re.split(r"[<>=;\[ ]", d, maxsplit=1)[0].lower() for d in project["dependencies"]]
    assert "pyserial" in names
    assert "pyrealsense2" not in names  # no aarch64 wheel on PyPI: a hard dependency would break the Jetson
    assert any(d.startswith("pyrealsense2") for d in project["optional-dependencies"]["realsense"])


def _rules(text: str) -> list[list[tuple[str, str, str]]]:
    return [RULE_FIELD.findall(line) for line in text.splitlines() if line.startswith("KERNEL==")]


def test_the_documented_udev_rules_name_the_devices_the_hardware_launch_file_opens() -> None:
    rules = _rules(DOCS)
    links = {value for rule in rules for key, op, value in rule if (key, op) == ("SYMLINK", "+=")}
    assert links == {"rplidar", "arduino"}
    for rule in rules:  # each matches a serial adapter by its USB vendor id
        keys = [key for key, _op, _value in rule]
        assert keys[0] == "KERNEL" and "ATTRS{idVendor}" in keys, rule
    # the script writes the documented lidar rule
    assert _rules(RULE) == [r for r in rules if ("SYMLINK", "+=", "rplidar") in r]
    launch = (ROOT / "examples/puzzlebot_hw/launch/puzzlebot_hw.launch").read_text()
    assert '<arg name="arduino_port" default="/dev/arduino"/>' in launch
    assert '<arg name="lidar_port" default="/dev/rplidar"/>' in launch
