"""dynamic_reconfigure against Debian's real ROS 1: its dynparam drives our Server, our Client drives its Server."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from dyn_fixtures import load_module, write_tutorial_module

from ninjemys.dynamic_reconfigure.client import ReconfigureClient
from ninjemys.dynamic_reconfigure.server import ReconfigureServer
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import ROS1_PYTHON, ros1_env

pytestmark = pytest.mark.ros1

DYNPARAM = "/usr/lib/dynamic_reconfigure/dynparam"
PACKAGE_XML = (
    Path(__file__).parents[2] / "src" / "ninjemys" / "interfaces" / "dynamic_reconfigure" / "package.xml"
)


@pytest.fixture
def master_uri(monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    with MasterThread() as uri:
        monkeypatch.setenv("ROS_MASTER_URI", uri)
        yield uri


@pytest.fixture
def cfg_dir(tmp_path: Path) -> Path:
    write_tutorial_module(tmp_path)
    # Debian's dynparam calls roslib.load_manifest('dynamic_reconfigure'), and Debian ships no package.xml
    share = tmp_path / "share" / "dynamic_reconfigure"
    share.mkdir(parents=True)
    (share / "package.xml").write_text(PACKAGE_XML.read_text())
    return tmp_path


def ros1(master_uri: str, cfg_dir: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = ros1_env(master_uri, ROS_PACKAGE_PATH=str(cfg_dir / "share"), PYTHONPATH=str(cfg_dir))
    return subprocess.run([ROS1_PYTHON, *args], env=env, capture_output=True, text=True, timeout=60)


def ours(master_uri: str, *args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "ninjemys.packages.run_shipped", "dynamic_reconfigure", "dynparam", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60)


def test_ros1_dynparam_sets_our_server(master_uri: str, cfg_dir: Path) -> None:
    tutorials = load_module(cfg_dir / "TutorialsConfig.py")
    node = Node("dyn_server", master_uri=master_uri)
    levels: list[int] = []

    def callback(config, level):
        levels.append(level)
        return config

    try:
        ReconfigureServer(node, tutorials, callback)
        done = ros1(master_uri, cfg_dir, DYNPARAM, "set", "/dyn_server", "int_param", "64")
        assert done.returncode == 0, done.stderr
        done = ros1(
            master_uri, cfg_dir, DYNPARAM, "set", "/dyn_server", "{'size': 'ExtraLarge', 'max_speed': 9}"
        )
        assert done.returncode == 0, done.stderr
        assert levels == [-1, 0, 1 | 4]
        assert node.get_param("~int_param") == 64 and node.get_param("~max_speed") == 5.0
        assert node.get_param("~size") == 3

        theirs_get = ros1(master_uri, cfg_dir, DYNPARAM, "get", "/dyn_server")
        ours_get = ours(master_uri, "get", "/dyn_server")
        assert theirs_get.returncode == ours_get.returncode == 0, ours_get.stderr
        assert ours_get.stdout == theirs_get.stdout
        assert "'int_param': 64" in ours_get.stdout

        for who, run in (
            ("theirs", lambda *a: ros1(master_uri, cfg_dir, DYNPARAM, *a)),
            ("ours", lambda *a: ours(master_uri, *a)),
        ):
            assert run("dump", "/dyn_server", str(cfg_dir / f"{who}.yaml")).returncode == 0
        assert (cfg_dir / "ours.yaml").read_text() == (cfg_dir / "theirs.yaml").read_text()

        assert ours(master_uri, "set", "/dyn_server", "int_param", "1").returncode == 0
        assert (
            ros1(master_uri, cfg_dir, DYNPARAM, "load", "/dyn_server", str(cfg_dir / "ours.yaml")).returncode
            == 0
        )
        assert node.get_param("~int_param") == 64
        assert ours(master_uri, "set", "/dyn_server", "int_param", "2").returncode == 0
        assert ours(master_uri, "load", "/dyn_server", str(cfg_dir / "theirs.yaml")).returncode == 0
        assert node.get_param("~int_param") == 64

        listed = ros1(master_uri, cfg_dir, DYNPARAM, "list")
        assert listed.stdout == ours(master_uri, "list").stdout == "/dyn_server\n"
    finally:
        node.shutdown("test over")


ROS1_SERVER = textwrap.dedent(
    """
    import rospy
    from dynamic_reconfigure.server import Server
    import TutorialsConfig

    def callback(config, level):
        rospy.set_param("~last_level", level)
        return config

    rospy.init_node("ros1_dyn_server")
    Server(TutorialsConfig, callback)
    print("ready", flush=True)
    rospy.spin()
    """
)


def test_our_client_against_ros1_server(master_uri: str, cfg_dir: Path) -> None:
    (cfg_dir / "server.py").write_text(ROS1_SERVER)
    env = ros1_env(master_uri, ROS_PACKAGE_PATH=str(cfg_dir / "share"), PYTHONPATH=str(cfg_dir))
    proc = subprocess.Popen(
        [ROS1_PYTHON, str(cfg_dir / "server.py"), "_int_param:=12"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    node = Node("dyn_client", master_uri=master_uri)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "ready"
        client = ReconfigureClient(node, "/ros1_dyn_server", timeout=20.0)
        config = client.get_configuration(timeout=10.0)
        assert config["int_param"] == 12 and config["str_param"] == "Hello World"
        assert config["groups"]["groups"]["Limits"]["groups"]["Inner"]["state"] is False
        result = client.update_configuration({"double_param": 0.75, "size": "Large", "inner_flag": True})
        assert (result["double_param"], result["size"], result["inner_flag"]) == (0.75, 2, True)
        assert node.get_param("/ros1_dyn_server/last_level") == 0 | 1 | 8
        assert node.get_param("/ros1_dyn_server/double_param") == 0.75
        deadline = time.monotonic() + 10
        while client.config["double_param"] != 0.75 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert client.config["double_param"] == 0.75
        client.close()
    finally:
        node.shutdown("test over")
        proc.kill()
        proc.wait()


@pytest.mark.parametrize("args", [[], ["set", "-h"], ["set", "a"], ["load", "a"]])
def test_usage_and_argument_errors_match(cfg_dir: Path, args: list[str]) -> None:
    theirs = ros1("http://localhost:1/", cfg_dir, DYNPARAM, *args)
    mine = subprocess.run(
        [sys.executable, "-m", "ninjemys.packages.run_shipped", "dynamic_reconfigure", "dynparam", *args],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (mine.returncode, mine.stdout, mine.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr)
