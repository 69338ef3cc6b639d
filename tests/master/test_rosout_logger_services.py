"""roscore's /rosout node offers /rosout/get_loggers and /rosout/set_logger_level, as real rosout does."""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys.errors import MasterError
from ninjemys.idl.loader import get_service_class
from ninjemys.master.client import MasterClient
from ninjemys.node import Node
from ninjemys.testing import ROS1_BIN, free_port, have_ros1, kill_tree, ros1_env, run_master


def _services_of(uri: str, node: str) -> list[str]:
    state = MasterClient(uri, "/test").get_system_state()
    return sorted(name for name, providers in state[2] if node in providers)


def _wait_for_service(uri: str, name: str, timeout: float = 20.0) -> None:
    client = MasterClient(uri, "/test", timeout=5)
    deadline = time.monotonic() + timeout
    while True:
        try:
            client.lookup_service(name)
            return
        except MasterError:
            assert time.monotonic() < deadline, f"{name} never registered"
            time.sleep(0.05)


def _rosout_node_graph(uri: str) -> tuple[list[str], list[str]]:
    """(publications, services) of the /rosout node, from the master's system state."""
    pubs, _subs, srvs = MasterClient(uri, "/test").get_system_state()
    return (
        sorted(topic for topic, nodes in pubs if "/rosout" in nodes),
        sorted(name for name, nodes in srvs if "/rosout" in nodes),
    )


@pytest.fixture
def our_roscore(tmp_path: Path) -> Iterator[str]:
    env = dict(os.environ, ROS_HOME=str(tmp_path / "home"), ROS_HOSTNAME="localhost")
    env.pop("ROS_LOG_DIR", None)
    with run_master(env=env) as uri:
        _wait_for_service(uri, "/rosout/set_logger_level")
        yield uri


def test_rosout_serves_get_loggers_and_set_logger_level(our_roscore: str) -> None:
    pubs, services = _rosout_node_graph(our_roscore)
    assert services == ["/rosout/get_loggers", "/rosout/set_logger_level"]
    assert pubs == ["/rosout_agg"]  # rosout does not log to /rosout itself (roscpp's NoRosout)
    with Node("logger_client", master_uri=our_roscore, rosout=False, logger_services=False) as node:
        get = node.service_proxy("/rosout/get_loggers", get_service_class("roscpp/GetLoggers"))
        set_level = node.service_proxy("/rosout/set_logger_level", get_service_class("roscpp/SetLoggerLevel"))
        assert {lg.name: lg.level for lg in get().loggers}["rosout"] == "info"
        set_level(logger="rosout", level="warn")
        assert {lg.name: lg.level for lg in get().loggers}["rosout"] == "warn"


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="needs Debian's ROS 1")
def test_rosservice_list_matches_real_roscore(our_roscore: str, tmp_path: Path) -> None:
    """Debian's ``rosservice list`` and ``rosservice call /rosout/get_loggers`` see the same /rosout
    services on our roscore as on Debian's."""
    port = free_port()
    real_uri = f"http://localhost:{port}/"
    home = tmp_path / "real_home"
    real = subprocess.Popen(
        [str(ROS1_BIN / "roscore"), "-p", str(port)],
        env=ros1_env(real_uri, ROS_HOME=str(home), HOME=str(home)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
    )
    try:
        _wait_for_service(real_uri, "/rosout/set_logger_level", timeout=30)
        listed = {}
        for uri in (real_uri, our_roscore):
            env = ros1_env(uri, ROS_HOME=str(home), HOME=str(home))
            out = subprocess.run(
                [str(ROS1_BIN / "rosservice"), "list"], env=env, capture_output=True, text=True, timeout=30
            )
            assert out.returncode == 0, out.stderr
            listed[uri] = out.stdout
            call = subprocess.run(
                [str(ROS1_BIN / "rosservice"), "call", "/rosout/set_logger_level", "ros", "info"],
                env=env,
                capture_output=True,
                text=True,
                timeout=30,
            )
            assert call.returncode == 0, call.stderr
        assert listed[our_roscore] == listed[real_uri] == "/rosout/get_loggers\n/rosout/set_logger_level\n"
        assert _rosout_node_graph(our_roscore) == _rosout_node_graph(real_uri)
    finally:
        # SIGKILL to Debian's roslaunch and its rosmaster and rosout: its own SIGINT shutdown takes ~2 s
        # and nothing here is about it (ROS_HOME is the test's own directory)
        kill_tree(real)
