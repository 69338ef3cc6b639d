"""Each shipped interface package is a real ROS package: package.xml with its name, version and deps.

rospack, ``$(find pkg)`` and catkin rely on package.xml; a package whose definitions use another
package's types must declare it, as catkin's generate_messages(DEPENDENCIES ...) would require.
"""

from __future__ import annotations

import json
import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from iface_inventory import INTERFACES, SHIPPED_PACKAGES

from ninjemys.idl.spec import BUILTIN_TYPES
from ninjemys.testing import ROS1_PYTHON, ros1_env


def _manifest(pkg: str) -> ET.Element:
    return ET.parse(INTERFACES / pkg / "package.xml").getroot()


def _used_packages(pkg: str) -> set[str]:
    used: set[str] = set()
    for path in (INTERFACES / pkg).glob("*/*"):
        if path.suffix == ".action":
            used |= {"actionlib_msgs", "std_msgs"}  # the generated ActionGoal/Result/Feedback messages
        if path.suffix not in (".msg", ".srv", ".action"):
            continue
        for line in path.read_text().splitlines():
            line = line.strip()
            if not line or line == "---" or "=" in line:
                continue
            base = re.sub(r"\[\d*\]$", "", line.split()[0])
            if base == "Header":
                used.add("std_msgs")
            elif base not in BUILTIN_TYPES and "/" in base:
                used.add(base.split("/")[0])
    used.discard(pkg)
    return used


def test_exactly_the_shipped_packages_are_there() -> None:
    assert sorted(
        p.name for p in INTERFACES.iterdir() if p.is_dir() and not p.name.startswith("_")
    ) == sorted(SHIPPED_PACKAGES)


@pytest.mark.parametrize("pkg", SHIPPED_PACKAGES)
def test_manifest_names_the_package_and_declares_its_message_deps(pkg: str) -> None:
    root = _manifest(pkg)
    assert root.tag == "package" and root.get("format") == "2"
    assert root.findtext("name") == pkg
    assert re.fullmatch(r"\d+\.\d+\.\d+", root.findtext("version") or "")
    declared = {e.text for e in root if e.tag in ("depend", "build_depend", "exec_depend")}
    assert _used_packages(pkg) <= declared
    assert {"message_generation", "message_runtime"} <= declared


@pytest.mark.parametrize("pkg", SHIPPED_PACKAGES)
def test_definitions_carry_no_prose_comments(pkg: str) -> None:
    """Definitions are written from the type facts; the original files' comments are not shipped."""
    for path in (INTERFACES / pkg).glob("*/*"):
        if path.suffix in (".msg", ".srv", ".action"):
            assert "#" not in path.read_text(), path


ROSPKG_SCRIPT = """
import json, sys, warnings
import catkin_pkg.package
import rospkg
rp = rospkg.RosPack()
out = {}
for name in sys.argv[1:]:
    path = rp.get_path(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # catkin_pkg warns about anything non-conforming
        manifest = catkin_pkg.package.parse_package(path)
    out[name] = {"path": path, "name": manifest.name, "deps": [d.name for d in manifest.exec_depends]}
print(json.dumps(out))
"""


@pytest.mark.ros1
def test_real_ros_tools_find_and_validate_every_package(tmp_path: Path) -> None:
    """Debian's rospkg (rospack, roslaunch, rosmsg) finds our packages; catkin_pkg validates the manifests."""
    env = ros1_env("http://localhost:11311", ROS_PACKAGE_PATH=str(INTERFACES), ROS_HOME=str(tmp_path))
    done = subprocess.run(
        [ROS1_PYTHON, "-c", ROSPKG_SCRIPT, *SHIPPED_PACKAGES],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout)
    for pkg in SHIPPED_PACKAGES:
        if pkg in ("std_srvs", "actionlib"):  # Debian's own copies under /usr/share may win the lookup
            continue
        assert Path(found[pkg]["path"]) == INTERFACES / pkg
        assert found[pkg]["name"] == pkg
        assert _used_packages(pkg) <= set(found[pkg]["deps"])
