"""Bash completion: bash itself sources ninjemys.bash and runs the completion functions against a live
ninjemys graph (our roscore, a ninjemys talker with /chatter, a latched /status and the /set_flag
service); plus the helper's pieces (XML-RPC decoding, package scans, prototypes) on their own."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
import xmlrpc.client
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from graph_procs import graph  # noqa: E402

from ninjemys.testing import free_port, ninjemys_bin, run_master  # noqa: E402
from ninjemys.tools import complete, complete_pkgs, complete_proto  # noqa: E402

BASH_FILE = complete.BASH_FILE


def complete_words(words: list[str], env: dict[str, str], cwd: Path | None = None) -> list[str]:
    """COMPREPLY of the completion function bash registered for ``words[0]``, completing the last word."""
    quoted = " ".join(shlex.quote(w) for w in words)
    script = (
        f"source {shlex.quote(BASH_FILE)}\n"
        f"COMP_WORDS=({quoted}); COMP_CWORD={len(words) - 1}; COMPREPLY=()\n"
        'fn=$(complete -p "${COMP_WORDS[0]}" | sed -E "s/.*-F ([^ ]+).*/\\1/")\n'
        '"$fn"\n'
        'printf "%s\\0" "${COMPREPLY[@]}"\n'
    )
    done = subprocess.run(
        ["bash", "--norc", "--noprofile", "-c", script],
        env=env,
        cwd=cwd,
        capture_output=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr.decode()
    assert done.stderr == b"", done.stderr.decode()
    return [w for w in done.stdout.decode().split("\0") if w]


def bash_env(master_uri: str, **extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env.update(ROS_MASTER_URI=master_uri, NINJEMYS_PYTHON=sys.executable, ROS_HOSTNAME="localhost")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env.update(extra)
    return env


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory):
    tmp = tmp_path_factory.mktemp("completion")
    with run_master() as uri:
        with graph(uri, tmp, rate_hz=5.0, listener=False):
            client = xmlrpc.client.ServerProxy(uri)
            client.setParam("/test", "/completion/gain", 2.5)
            client.setParam("/test", "/completion/sub/name", "x")
            yield bash_env(uri)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A source space with one package holding a launch file, a message and an executable script."""
    src = tmp_path_factory.mktemp("ws") / "src"
    pkg = src / "demo_pkg"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "msg").mkdir()
    (pkg / "scripts").mkdir()
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>demo_pkg</name><version>0.1.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer><license>BSD</license>"
        "<buildtool_depend>catkin</buildtool_depend></package>\n"
    )
    (pkg / "launch" / "demo.launch").write_text(
        '<launch>\n  <arg name="rate" default="10"/>\n  <arg name="robot"/>\n  <arg name="fixed" value="1"/>\n'
        '  <group ns="g"><arg name="in_group" default="a"/></group>\n'
        '  <include file="other.launch"><arg name="passed" value="2"/></include>\n</launch>\n'
    )
    (pkg / "msg" / "Reading.msg").write_text("float64 value\n")
    script = pkg / "scripts" / "sensor_node.py"
    script.write_text("#!/usr/bin/env python3\n")
    script.chmod(0o755)
    (pkg / "scripts" / "not_executable.py").write_text("x = 1\n")
    return src


# -- against the live graph --------------------------------------------------------------------------


def test_rostopic_subcommands_and_topics(live):
    assert complete_words(["rostopic", ""], live) == [
        "bw",
        "delay",
        "echo",
        "find",
        "hz",
        "info",
        "list",
        "pub",
        "type",
    ]
    assert complete_words(["rostopic", "echo", "/ch"], live) == ["/chatter"]
    assert complete_words(["rostopic", "hz", "/chatter", "/st"], live) == ["/status"]
    # options and their values are skipped when counting positionals
    assert complete_words(["rostopic", "echo", "-n", "1", "/st"], live) == ["/status"]
    assert set(complete_words(["rostopic", "info", ""], live)) >= {"/chatter", "/status", "/rosout"}


def test_rostopic_pub_completes_type_then_prototype(live):
    # the seed's `rostopic pub /chatter <tab complete>`
    assert complete_words(["rostopic", "pub", "/chatter", ""], live) == ["std_msgs/String"]
    assert complete_words(["rostopic", "pub", "/chatter", "std_msgs/String", ""], live) == ["\"data: ''\""]
    assert complete_words(["rostopic", "pub", "-r", "10", "/chatter", "std_msgs/String", ""], live) == [
        "\"data: ''\""
    ]
    twist = complete_words(["rostopic", "pub", "/turtle1/cmd_vel", "geometry_msgs/Twist", ""], live)
    assert twist == ['"linear:\n  x: 0.0\n  y: 0.0\n  z: 0.0\nangular:\n  x: 0.0\n  y: 0.0\n  z: 0.0"']
    # a topic nobody has registered yet: any message type
    assert complete_words(["rostopic", "pub", "/new", "geometry_msgs/Twi"], live) == [
        "geometry_msgs/Twist",
        "geometry_msgs/TwistStamped",
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/TwistWithCovarianceStamped",
    ]


def test_rostopic_pub_prototype_is_what_rostopic_pub_accepts(live):
    (proto,) = complete_words(["rostopic", "pub", "/pose_in", "geometry_msgs/PoseStamped", ""], live)
    done = subprocess.run(
        [ninjemys_bin("rostopic"), "pub", "-1", "/pose_in", "geometry_msgs/PoseStamped", proto.strip('"')],
        env=live,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr


def test_rosnode_rosservice_rosparam(live):
    assert complete_words(["rosnode", "info", "/ta"], live) == ["/talker"]
    assert complete_words(["rosnode", "kill", "/talker", "/ros"], live) == ["/rosout"]
    assert complete_words(["rosnode", "p"], live) == ["ping"]
    assert complete_words(["rosservice", "call", "/set"], live) == ["/set_flag"]
    assert complete_words(["rosservice", "call", "/set_flag", ""], live) == ['"data: false"']
    assert complete_words(["rosservice", "find", "std_srvs/S"], live) == ["std_srvs/SetBool"]
    assert complete_words(["rosparam", "get", "/completion/"], live) == [
        "/completion/",
        "/completion/gain",
        "/completion/sub/",
        "/completion/sub/name",
    ]
    assert complete_words(["rosparam", "delete", "/run"], live) == ["/run_id"]
    assert complete_words(["rosbag", "record", "-O", "out.bag", "/ch"], live) == ["/chatter"]
    assert complete_words(["rosbag", "record", "--node", "/ta"], live) == ["/talker"]


def test_options_offered_are_accepted_by_the_tools(live):
    """Every option the completion offers appears in the tool's own -h (catches drift)."""
    cases = [
        ["rostopic", "echo"],
        ["rostopic", "list"],
        ["rostopic", "pub"],
        ["rostopic", "hz"],
        ["rosnode", "ping"],
        ["rosnode", "list"],
        ["rosservice", "call"],
        ["rosparam", "set"],
        ["rosparam", "get"],
        ["rosbag", "record"],
        ["rosbag", "play"],
        ["rosbag", "info"],
        ["roscore"],
        ["roslaunch"],
        ["catkin_make"],
        ["catkin_create_pkg"],
    ]
    for case in cases:
        offered = complete_words([*case, "-"], live)
        assert "-h" in offered, case
        helped = subprocess.run(
            [ninjemys_bin(case[0]), *case[1:], "-h"], env=live, capture_output=True, text=True, timeout=30
        )
        usage = helped.stdout + helped.stderr
        for option in offered:
            assert option in usage, f"{' '.join(case)}: completion offers {option}, -h does not list it"


def test_dead_master_gives_no_candidates_and_no_noise(tmp_path):
    env = bash_env(f"http://localhost:{free_port()}/")
    assert complete_words(["rostopic", "echo", ""], env) == []
    assert complete_words(["rosnode", "info", ""], env) == []
    assert complete_words(["rosparam", "get", ""], env) == []
    # static parts keep working
    assert complete_words(["rosparam", "l"], env) == ["list", "load"]


# -- packages, types, launch files -------------------------------------------------------------------


def test_package_kinds(workspace, tmp_path):
    env = bash_env(f"http://localhost:{free_port()}/", ROS_PACKAGE_PATH=str(workspace))
    assert complete_words(["roscd", "demo_"], env) == ["demo_pkg"]
    assert complete_words(["roscd", "demo_pkg/"], env) == [
        "demo_pkg/launch/",
        "demo_pkg/msg/",
        "demo_pkg/scripts/",
    ]
    assert complete_words(["rosls", "demo_pkg/launch/"], env) == ["demo_pkg/launch/demo.launch"]
    assert complete_words(["rosed", "demo_pkg", "demo"], env) == ["demo.launch"]
    assert complete_words(["rosrun", "demo"], env) == ["demo_pkg"]
    assert complete_words(["rosrun", "demo_pkg", ""], env) == ["sensor_node.py"]
    assert "turtlesim_node" in complete_words(["rosrun", "turtlesim", ""], env)
    assert complete_words(["rosrun", "turtlesim", "turtlesim_node", "__na"], env) == ["__name:="]
    assert complete_words(["roslaunch", "demo_pkg", ""], env) == ["demo.launch"]
    assert complete_words(["roslaunch", "demo_pkg", "demo.launch", ""], env) == [
        "rate:=",
        "robot:=",
        "in_group:=",
    ]
    assert complete_words(["roslaunch", "demo_pkg", "demo.launch", "rate:=1", "ro"], env) == ["robot:="]
    launch = workspace / "demo_pkg" / "launch" / "demo.launch"
    assert complete_words(["roslaunch", str(launch), "r"], env) == ["rate:=", "robot:="]
    assert complete_words(["rosmsg", "show", "demo_pkg/"], env) == ["demo_pkg/Reading"]
    assert complete_words(["rosmsg", "package", "demo"], env) == ["demo_pkg"]
    assert complete_words(["rospack", "find", "demo"], env) == ["demo_pkg"]
    assert complete_words(["catkin_create_pkg", "new_pkg", "std_m"], env) == ["std_msgs"]
    (tmp_path / "a.bag").write_bytes(b"")
    (tmp_path / "notes.txt").write_text("")
    assert complete_words(["rosbag", "info", ""], env, cwd=tmp_path) == ["a.bag"]


def test_package_names_match_package_discovery(workspace, monkeypatch):
    from ninjemys.packages.discovery import PackageIndex

    monkeypatch.setenv("ROS_PACKAGE_PATH", str(workspace))
    ours = complete_pkgs.packages()
    index = PackageIndex.from_environment()
    assert sorted(ours) == index.names()
    assert Path(ours["demo_pkg"]) == index.find("demo_pkg").path


def test_interface_types_match_the_message_search(workspace, monkeypatch):
    from ninjemys.idl import search

    monkeypatch.setenv("ROS_PACKAGE_PATH", str(workspace))
    search.clear_cache()
    try:
        for kind in ("msg", "srv"):
            expected = sorted(
                f"{name}/{short}"
                for name, pkg in search.packages().items()
                for short in pkg.definitions(kind)
            )
            assert complete_pkgs.interface_types(kind) == expected
    finally:
        search.clear_cache()


# -- the helper's pieces -----------------------------------------------------------------------------


def test_decode_response_handles_what_xmlrpc_servers_send():
    value = [1, "ok", [["/a&b", ["/n<1>"]], [], [[True, 3, 2.5, "", {"k": ["v"]}]]]]
    body = xmlrpc.client.dumps((value,), methodresponse=True)
    assert complete.decode_response(body) == value
    untyped = "<methodResponse><params><param><value><array><data><value>x y</value><value/></data></array></value></param></params></methodResponse>"
    assert complete.decode_response(untyped) == ["x y", ""]
    fault = xmlrpc.client.dumps(xmlrpc.client.Fault(1, "no"), methodresponse=True)
    assert complete.decode_response(fault) is None


def test_helper_stays_light():
    """A Tab press must not pay for the socket wrapper, xmlrpc.client, yaml or the message loader."""
    code = (
        "import sys\nfrom ninjemys.tools.complete import main\nmain(['topics', ''])\nmain(['msgs', 'std'])\n"
        "main(['packages', ''])\n"
        "heavy = [m for m in ('socket', 'xmlrpc.client', 'yaml', 'ninjemys.idl.loader', 'dataclasses', 're')"
        " if m in sys.modules]\nprint('HEAVY', heavy)\n"
    )
    env = bash_env(f"http://localhost:{free_port()}/")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "HEAVY []"


def test_unknown_kind_is_one_error_line():
    done = subprocess.run(
        [sys.executable, "-m", "ninjemys.tools.complete", "bogus", ""],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 2
    assert done.stderr == "ERROR: unknown completion kind [bogus]\n"
    assert complete.candidates("msg-proto", ["no_such/Type", ""]) == []
    missing = subprocess.run(
        [sys.executable, "-m", "ninjemys.tools.complete"], capture_output=True, text=True, timeout=30
    )
    assert missing.returncode == 2 and missing.stderr.startswith("ERROR: missing completion kind")
    assert missing.stdout == ""


@pytest.mark.ros1
@pytest.mark.parametrize(
    "type_name",
    [
        "std_msgs/String",
        "std_msgs/Header",
        "geometry_msgs/Twist",
        "geometry_msgs/PoseStamped",
        "sensor_msgs/JointState",
        "sensor_msgs/Imu",
        "std_msgs/Float64MultiArray",
        "nav_msgs/Path",
        "visualization_msgs/Marker",
    ],
)
def test_prototype_matches_rosmsg_proto(type_name):
    ref = subprocess.run(
        ["/usr/bin/rosmsg-proto", "msg", type_name], capture_output=True, text=True, timeout=60
    )
    assert ref.returncode == 0, ref.stderr
    assert complete_proto.message_prototype(type_name) == ref.stdout.rstrip("\n")


@pytest.mark.ros1
def test_request_prototype_matches_rosmsg_proto():
    for type_name in ("std_srvs/SetBool", "std_srvs/Trigger"):
        ref = subprocess.run(
            ["/usr/bin/rosmsg-proto", "srv", type_name], capture_output=True, text=True, timeout=60
        )
        assert complete_proto.request_prototype(type_name) == ref.stdout.rstrip("\n")


def test_byte_arrays_prototype_as_lists():
    assert "data: []" in complete_proto.message_prototype("sensor_msgs/Image")


# -- installation --------------------------------------------------------------------------------------


def test_ninjemys_completion_script_enables_completion(tmp_path):
    exe = ninjemys_bin("ninjemys-completion")
    path = subprocess.run([exe, "--path"], capture_output=True, text=True, timeout=30).stdout.strip()
    assert Path(path).is_file() and path == BASH_FILE
    script = (
        f'eval "$({shlex.quote(exe)})"\n'
        "complete -p rostopic rosnode rosservice rosparam rosmsg rossrv rosbag rospack roscd rosls rosed rosrun "
        "roslaunch roscore catkin_make catkin_create_pkg turtlesim_node\n"
        'printf "PY=%s\\n" "$_NJ_PY"\n'
        'printf "ROOT=%s\\n" "$_NJ_ROOT"\n'
        "_nj_run packages std_m\n"
    )
    env = dict(os.environ)
    env.pop("NINJEMYS_PYTHON", None)
    env["PATH"] = "/usr/bin:/bin"  # the interpreter comes from the eval'ed script, not from PATH
    done = subprocess.run(
        ["bash", "--norc", "-c", script], env=env, capture_output=True, text=True, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("complete -") >= 17
    assert f"PY={sys.executable}" in done.stdout
    assert f"ROOT={Path(complete.__file__).parents[2]}" in done.stdout
    assert "\nstd_msgs\n" in done.stdout  # the helper ran (python -S with that root on sys.path)
    bad = subprocess.run([exe, "--bogus"], capture_output=True, text=True, timeout=30)
    assert bad.returncode == 2 and bad.stderr.startswith("ERROR: ") and bad.stderr.count("\n") == 1


def test_interpreter_found_from_the_rostopic_shebang(tmp_path):
    """Sourced without ninjemys-completion or NINJEMYS_PYTHON, the helper runs under the interpreter
    of the rostopic found on PATH (a venv's python, not the system python3)."""
    script = f'source {shlex.quote(BASH_FILE)}\n_nj_python\nprintf %s "$_nj_py"\n'
    env = dict(os.environ)
    env.pop("NINJEMYS_PYTHON", None)
    env["PATH"] = f"{Path(ninjemys_bin('rostopic')).parent}{os.pathsep}/usr/bin:/bin"
    done = subprocess.run(
        ["bash", "--norc", "-c", script], env=env, capture_output=True, text=True, timeout=30
    )
    first = Path(ninjemys_bin("rostopic")).read_text().splitlines()[0]
    assert done.stdout == first.removeprefix("#!").strip()
