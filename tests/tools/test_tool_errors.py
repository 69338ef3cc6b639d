"""Bad input to the introspection tools: one clear line on stderr, non-zero exit, no traceback."""

from __future__ import annotations

import socket
import subprocess
import sys
import xmlrpc.client
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from graph_procs import ninjemys_env  # noqa: E402

from ninjemys.testing import free_port, ninjemys_bin, run_master  # noqa: E402


@pytest.fixture(scope="module")
def master_uri():
    with run_master() as uri:
        yield uri


def _tool(args: list[str], uri: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [ninjemys_bin(args[0]), *args[1:]], env=ninjemys_env(uri), capture_output=True, text=True, timeout=30
    )


def _one_clear_line(result: subprocess.CompletedProcess) -> str:
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert lines, result
    return lines[0]


def test_missing_master():
    uri = f"http://localhost:{free_port()}/"
    for args in (["rostopic", "list"], ["rosnode", "list"], ["rosparam", "get", "/"], ["rosservice", "list"]):
        assert _one_clear_line(_tool(args, uri)) == "ERROR: Unable to communicate with master!"


def test_unknown_type(master_uri):
    line = _one_clear_line(_tool(["rostopic", "pub", "/x", "foo/Bar", "{}"], master_uri))
    assert line == "ERROR: Cannot load message class for [foo/Bar]. Are your messages built?"


def test_malformed_yaml_names_the_position(master_uri):
    line = _one_clear_line(
        _tool(["rostopic", "pub", "-1", "/x", "std_msgs/String", "{data: [1,"], master_uri)
    )
    assert line.startswith("ERROR: Invalid YAML in argument 1")
    assert "line 1, column" in line
    line = _one_clear_line(_tool(["rosparam", "set", "/p", "{a: [1,"], master_uri))
    assert "invalid YAML" in line and "column" in line


def test_wrong_field_names_the_field(master_uri):
    line = _one_clear_line(
        _tool(["rostopic", "pub", "-1", "/x", "geometry_msgs/Twist", "{linear: {q: 1}}"], master_uri)
    )
    assert "linear.q" in line


def test_dead_node_in_graph(master_uri):
    """A node that registered and died without unregistering: info and ping say so in one line."""
    dead = socket.socket()
    dead.bind(("127.0.0.1", 0))
    uri = f"http://127.0.0.1:{dead.getsockname()[1]}/"
    dead.close()  # nothing listens there any more
    master = xmlrpc.client.ServerProxy(master_uri)
    code, _, _ = master.registerPublisher("/ghost", "/ghost_topic", "std_msgs/String", uri)
    assert code == 1
    ping = _tool(["rosnode", "ping", "-c", "1", "/ghost"], master_uri)
    assert ping.returncode != 0 and "Traceback" not in ping.stderr
    assert ping.stderr.strip() == f"ERROR: connection refused to [{uri}]"
    info = _tool(["rosnode", "info", "/ghost"], master_uri)
    assert "Node [/ghost]" in info.stdout and " * /ghost_topic [std_msgs/String]" in info.stdout
    assert info.stderr.strip() == f"ERROR: Communication with node[{uri}] failed!"


def test_unknown_topic_and_service(master_uri):
    assert _one_clear_line(_tool(["rostopic", "info", "/nope"], master_uri)) == "ERROR: Unknown topic /nope"
    assert _one_clear_line(_tool(["rosservice", "type", "/nope"], master_uri)) == "Unknown service [/nope]"
    assert (
        _one_clear_line(_tool(["rosparam", "get", "/nope"], master_uri))
        == "ERROR: Parameter [/nope] is not set"
    )
