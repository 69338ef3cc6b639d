"""Our Server, Client and dynparam together on one master."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from dyn_fixtures import load_module, write_tutorial_module

from ninjemys.dynamic_reconfigure.client import ReconfigureClient
from ninjemys.dynamic_reconfigure.errors import DynamicReconfigureParameterException
from ninjemys.dynamic_reconfigure.server import ReconfigureServer
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.tools import dynparam


@pytest.fixture
def master_uri(monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    with MasterThread() as uri:
        monkeypatch.setenv("ROS_MASTER_URI", uri)
        yield uri


@pytest.fixture
def tutorials(tmp_path: Path):
    return load_module(write_tutorial_module(tmp_path))


@pytest.fixture
def served(master_uri: str, tutorials) -> Iterator[tuple[Node, list[tuple[dict, int]]]]:
    node = Node(
        "dyn_server", master_uri=master_uri, params={"int_param": 7, "double_param": 1, "str_param": 3}
    )
    calls: list[tuple[dict, int]] = []

    def callback(config, level):
        calls.append((dict(config), level))
        return config

    ReconfigureServer(node, tutorials, callback)
    try:
        yield node, calls
    finally:
        node.shutdown("test over")


@pytest.fixture
def client_node(master_uri: str) -> Iterator[Node]:
    node = Node("dyn_client", master_uri=master_uri)
    try:
        yield node
    finally:
        node.shutdown("test over")


def test_server_start_reads_and_writes_parameter_server(served) -> None:
    node, calls = served
    # int_param from the parameter server; an int for a double is converted; a number for a str refused
    assert calls[0][1] == -1
    assert (calls[0][0]["int_param"], calls[0][0]["double_param"], calls[0][0]["str_param"]) == (
        7,
        1.0,
        "Hello World",
    )
    assert node.get_param("~double_param") == 1.0 and node.get_param("~size") == 1
    assert node.get_param("~str_param") == "Hello World"


def test_client_reads_updates_and_follows(served, client_node: Node) -> None:
    node, calls = served
    seen: list[dict] = []
    got = threading.Event()

    def on_config(config):
        seen.append(config)
        got.set()

    client = ReconfigureClient(client_node, "/dyn_server", timeout=5.0, config_callback=on_config)
    config = client.get_configuration(timeout=5.0)
    assert config["int_param"] == 7
    assert config["groups"]["groups"]["Limits"]["groups"]["Inner"]["state"] is False
    names = [p["name"] for p in client.get_parameter_descriptions(timeout=5.0)]
    assert names == [
        "int_param",
        "double_param",
        "str_param",
        "bool_param",
        "size",
        "max_speed",
        "inner_flag",
    ]
    assert set(client.get_group_descriptions(timeout=5.0)["groups"]) == {"Limits"}

    got.clear()
    result = client.update_configuration(
        {"int_param": 500, "size": "large", "bool_param": "false", "max_speed": 2}
    )
    assert (result["int_param"], result["size"], result["bool_param"], result["max_speed"]) == (
        100,
        2,
        False,
        2.0,
    )
    assert calls[-1][1] == 0 | 1 | 4  # the levels of the changed parameters
    assert node.get_param("~int_param") == 100
    assert got.wait(5.0)
    assert seen[-1]["int_param"] == 100

    result = client.update_configuration({"groups": {"Inner": True}})
    assert result["groups"]["groups"]["Limits"]["groups"]["Inner"]["state"] is True
    with pytest.raises(DynamicReconfigureParameterException, match="don't know parameter: nope"):
        client.update_configuration({"nope": 1})
    with pytest.raises(DynamicReconfigureParameterException, match="can't set parameter 'int_param'"):
        client.update_configuration({"int_param": "many"})
    client.close()


def test_dynparam_commands(served, tmp_path: Path, capsys) -> None:
    node, _calls = served
    assert dynparam.main(["list"]) == 0
    assert capsys.readouterr().out == "/dyn_server\n"
    assert dynparam.main(["set", "/dyn_server", "int_param", "42"]) == 0
    assert dynparam.main(["set", "/dyn_server", "{'str_param': 'yaml', 'size': 'Small'}"]) == 0
    capsys.readouterr()
    assert dynparam.main(["get", "-t", "5", "/dyn_server"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("{'bool_param': True, 'inner_flag': False, 'int_param': 42, 'size': 0,")
    dump = tmp_path / "dump.yaml"
    assert dynparam.main(["dump", "/dyn_server", str(dump)]) == 0
    assert dump.read_text().startswith("!!python/object/new:dynamic_reconfigure.encoding.Config\n")
    assert dynparam.main(["set", "/dyn_server", "int_param", "1"]) == 0
    assert dynparam.main(["load", "/dyn_server", str(dump)]) == 0
    assert node.get_param("~int_param") == 42
    plain = tmp_path / "plain.yaml"
    plain.write_text(yaml.safe_dump({"double_param": 0.25}))
    assert dynparam.main(["load", "/dyn_server", str(plain)]) == 0
    assert node.get_param("~double_param") == 0.25
    assert dynparam.main(["set", "/dyn_server", "int_param", "lots"]) == 0
    assert "error updating parameters: can't set parameter 'int_param'" in capsys.readouterr().out
    assert (
        dynparam.main(["set_from_parameters", "/dyn_server", "_int_param:=33", "_str_param:=from_params"])
        == 0
    )
    assert node.get_param("~int_param") == 33 and node.get_param("~str_param") == "from_params"
    capsys.readouterr()
    # ros_basic's param_pkg dumps to its author's /home/... path: one line, exit 1, no traceback
    missing = tmp_path / "no_such_dir" / "dump.yaml"
    assert dynparam.main(["dump", "/dyn_server", str(missing)]) == 1
    assert capsys.readouterr().err == f"ERROR: cannot write {missing}: No such file or directory\n"


def test_dynparam_errors(master_uri: str, capsys) -> None:
    assert dynparam.main([]) == 1
    assert "dynparam is a command-line tool" in capsys.readouterr().out
    assert dynparam.main(["get", "-t", "0.5", "/nobody"]) == 1
    assert capsys.readouterr().err.strip().endswith("/nobody/set_parameters")
    with pytest.raises(SystemExit) as exit_info:
        dynparam.main(["get"])
    assert exit_info.value.code == 2
    assert "invalid arguments. Please specify a node name" in capsys.readouterr().err


FACADE_PROGRAM = """
import rospy
from dynamic_reconfigure.server import Server
from dynamic_reconfigure.client import Client
import dynamic_reconfigure
import TutorialsConfig

rospy.init_node("facade_server")
levels = []
def callback(config, level):
    levels.append(level)
    return config
Server(TutorialsConfig, callback)
client = Client("facade_server", timeout=10)
result = client.update_configuration({"int_param": 9, "str_param": "set"})
print(result.int_param, result.str_param, levels, dynamic_reconfigure.find_reconfigure_services())
try:
    Client("/missing", timeout=0.2)
except rospy.ROSException as exc:
    print("ROSException", exc)
rospy.signal_shutdown("done")
"""


def test_rospy_facade_server_and_client(master_uri: str, tmp_path: Path) -> None:
    import os
    import subprocess
    import sys

    write_tutorial_module(tmp_path)
    (tmp_path / "prog.py").write_text(FACADE_PROGRAM)
    env = dict(os.environ, PYTHONPATH=str(tmp_path), ROS_MASTER_URI=master_uri)
    out = subprocess.run(
        [sys.executable, str(tmp_path / "prog.py")], env=env, capture_output=True, text=True, timeout=60
    )
    lines = out.stdout.splitlines()
    assert lines[0] == "9 set [-1, 0] ['/facade_server']", out.stderr
    assert lines[1].startswith("ROSException") and "/missing/set_parameters" in lines[1]


def test_server_refuses_bad_values_and_keeps_serving(served, client_node: Node, caplog) -> None:
    from ninjemys.dynamic_reconfigure.encoding import decode_config
    from ninjemys.idl.loader import get_message_class, get_service_class

    node, _calls = served
    msgs = "dynamic_reconfigure/"
    Reconfigure = get_service_class(msgs + "Reconfigure")
    config = get_message_class(msgs + "Config")()
    config.ints.append(get_message_class(msgs + "IntParameter")("nope", 1))
    config.strs.append(get_message_class(msgs + "StrParameter")("int_param", "many"))
    config.doubles.append(get_message_class(msgs + "DoubleParameter")("size", 2.0))
    proxy = client_node.service_proxy("/dyn_server/set_parameters", Reconfigure)
    reply = decode_config(proxy(config).config)
    assert reply["int_param"] == 7 and reply["size"] == 2 and "nope" not in reply
    assert "ignoring unknown parameter 'nope'" in caplog.text
    assert "parameter 'int_param' is int, got 'many'" in caplog.text
    assert node.get_param("~size") == 2
