"""``rosmsg`` / ``rossrv`` output, ours against Debian's real ROS 1, byte for byte.

Real rosmsg reads .msg files through rospack; Debian installs almost none, so both sides are pointed at
our interface directory with ROS_PACKAGE_PATH. A built ROS 1 package also holds the seven messages each
``.action`` generates (catkin runs genaction into its share directory): the real side reads a copy of our
interface directory into which Debian's own genaction.py has written them, as a build would. The definitions' facts are proven elsewhere (md5 tests);
here the rendering is: ROS 1 prints parsed fields (nested types expanded and indented, constants first),
so the output of the two programs over the same files must be identical.
"""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest
from iface_inventory import INTERFACES, inventory

from ninjemys.testing import ROS1_PYTHON, ninjemys_bin, ros1_built_interfaces, ros1_env

pytestmark = pytest.mark.ros1

INV = inventory()
ORACLE = Path(__file__).with_name("rosmsg_oracle.py")

CLI_CASES = [
    ["rosmsg", "show", "geometry_msgs/PoseStamped"],
    ["rosmsg", "md5", "sensor_msgs/Image"],
    ["rossrv", "show", "turtlesim/Spawn"],
    ["rosmsg", "show", "-r", "rosgraph_msgs/Log"],
    ["rosmsg", "show", "rosgraph_msgs/Log"],
    ["rosmsg", "show", "visualization_msgs/InteractiveMarkerUpdate"],
    ["rosmsg", "show", "Header"],
    ["rosmsg", "show", "Pose"],
    ["rossrv", "show", "nav_msgs/GetPlan"],
    ["rossrv", "md5", "nav_msgs/GetPlan"],
    ["rosmsg", "package", "turtlesim"],
    ["rosmsg", "package", "actionlib_tutorials"],
    ["rosmsg", "package", "move_base_msgs"],
    ["rosmsg", "show", "move_base_msgs/MoveBaseActionGoal"],
    ["rosmsg", "show", "-r", "control_msgs/FollowJointTrajectoryActionResult"],
    ["rosmsg", "show", "FibonacciFeedback"],
    ["rosmsg", "md5", "move_base_msgs/MoveBaseAction"],
    ["rossrv", "package", "roscpp"],
    ["rosmsg", "list"],
    ["rossrv", "list"],
    ["rosmsg", "packages"],
]


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return ros1_built_interfaces(tmp_path_factory.mktemp("built"))


def _env(tmp_path: Path, packages: Path = INTERFACES) -> dict[str, str]:
    return ros1_env("http://localhost:11311", ROS_PACKAGE_PATH=str(packages), HOME=str(tmp_path))


def _ours(tmp_path: Path, argv: list[str]) -> subprocess.CompletedProcess[str]:
    try:
        exe = ninjemys_bin(argv[0])
    except FileNotFoundError:
        pytest.skip(f"our {argv[0]} is not installed yet")
    env = _env(tmp_path)
    env["PATH"] = f"{Path(exe).parent}:{env['PATH']}"
    return subprocess.run([exe, *argv[1:]], env=env, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("argv", CLI_CASES, ids=" ".join)
def test_cli_output_is_byte_identical(argv: list[str], tmp_path: Path, built: Path) -> None:
    ours = _ours(tmp_path, argv)
    theirs = subprocess.run(
        [f"/usr/bin/{argv[0]}", *argv[1:]],
        env=_env(tmp_path, built),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert theirs.returncode == 0, theirs.stderr
    assert ours.returncode == 0, ours.stderr
    expected = theirs.stdout
    if argv[1] in ("list", "packages"):
        # Debian installs its own std_srvs and actionlib under /usr/share, which real rospack finds
        # besides ours and lists twice; a user's machine has one of each package
        expected = "".join(dict.fromkeys(expected.splitlines(keepends=True)))
    elif argv[1] == "show" and "/" not in argv[2]:
        # a bare type name is shown once per package that has it: Debian's std_msgs (ros-std-msgs, for
        # the C++ build tests) is found besides ours, so the same block comes twice
        expected = "".join(dict.fromkeys(re.split(r"(?<=\n\n)", expected)))
    assert ours.stdout == expected


def _real_texts(tmp_path: Path, built: Path, mode: str, raw: bool, types: list[str]) -> dict[str, str]:
    done = subprocess.run(
        [ROS1_PYTHON, str(ORACLE), mode, "1" if raw else "0", *types],
        env=_env(tmp_path, built),
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return json.loads(done.stdout)


@pytest.mark.parametrize("raw", [False, True], ids=["show", "show-r"])
@pytest.mark.parametrize("mode", ["msg", "srv"])
def test_show_of_every_type_matches(mode: str, raw: bool, tmp_path: Path, built: Path) -> None:
    """Every msg (action-generated ones too) and every srv through both programs; one process per side."""
    types = list(INV.messages) if mode == "msg" else list(INV.services)
    theirs = _real_texts(tmp_path, built, mode, raw, types)
    script = (
        "import contextlib, io, json, sys\n"
        f"from ninjemys.tools.ros{mode} import main\n"
        "out = {}\n"
        "for t in sys.argv[2:]:\n"
        "    buf = io.StringIO()\n"
        "    with contextlib.redirect_stdout(buf):\n"
        "        main(['show', *(['-r'] if sys.argv[1] == '1' else []), t])\n"
        "    out[t] = buf.getvalue()\n"
        "print(json.dumps(out))\n"
    )
    try:
        python = str(Path(ninjemys_bin(f"ros{mode}")).parent / "python")
    except FileNotFoundError:
        pytest.skip(f"our ros{mode} is not installed yet")
    env = _env(tmp_path)
    done = subprocess.run(
        [python, "-c", script, "1" if raw else "0", *types],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    ours = json.loads(done.stdout)
    # the CLI prints the text plus one newline (print()); compare on that exact form
    mismatched = [t for t in types if ours[t] != theirs[t] + "\n"]
    assert mismatched == [], (
        f"first mismatch {mismatched[0]}:\nours:\n{ours[mismatched[0]]}\ntheirs:\n{theirs[mismatched[0]]}"
    )
