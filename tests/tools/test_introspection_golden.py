"""Golden tests: for one fixed graph (ninjemys nodes + a real rospy node), our rosnode/rostopic/
rosservice/rosparam print exactly what Debian's real tools print against the same master — over our
roscore and over the real one (modulo pids, ports and timings)."""

from __future__ import annotations

import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from graph_procs import graph, normalize, real_roscore, run_tool  # noqa: E402

from ninjemys.testing import run_master  # noqa: E402

pytestmark = pytest.mark.ros1

GOLDEN = [
    ("rosnode", ["list"]),
    ("rosnode", ["list", "-a"]),
    ("rosnode", ["list", "-u"]),
    ("rosnode", ["info", "/talker"]),
    ("rosnode", ["info", "-q", "/listener"]),
    ("rosnode", ["machine"]),
    ("rosnode", ["machine", "localhost"]),
    ("rostopic", ["list"]),
    ("rostopic", ["list", "-v"]),
    ("rostopic", ["list", "-p"]),
    ("rostopic", ["list", "-s"]),
    ("rostopic", ["info", "/chatter"]),
    ("rostopic", ["type", "/chatter"]),
    ("rostopic", ["type", "/chatter/data"]),
    ("rostopic", ["find", "std_msgs/String"]),
    ("rostopic", ["echo", "-n", "1", "/status"]),
    ("rosservice", ["list"]),
    ("rosservice", ["list", "-n"]),
    ("rosservice", ["info", "/set_flag"]),
    ("rosservice", ["type", "/set_flag"]),
    ("rosservice", ["uri", "/set_flag"]),
    ("rosservice", ["args", "/set_flag"]),
    ("rosservice", ["find", "std_srvs/SetBool"]),
    ("rosservice", ["call", "/set_flag", "true"]),
    ("rosservice", ["call", "/set_flag", "{data: false}"]),
    ("rosparam", ["list"]),
    ("rosparam", ["get", "/"]),
    ("rosparam", ["get", "-p", "/"]),
]


@pytest.fixture(scope="module", params=["ninjemys_master", "ros1_master"])
def live_graph(request, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("graph")
    master = run_master() if request.param == "ninjemys_master" else real_roscore()
    with master as uri, graph(uri, tmp) as procs:
        yield uri, procs


@pytest.mark.parametrize("tool,args", GOLDEN, ids=[" ".join([t, *a]) for t, a in GOLDEN])
def test_output_matches_ros1(live_graph, tool, args):
    uri, _ = live_graph
    ours = run_tool(tool, args, uri, real=False)
    theirs = run_tool(tool, args, uri, real=True)
    assert theirs.returncode == 0, theirs.stderr
    assert ours.returncode == 0, ours.stderr
    assert normalize(ours.stdout) == normalize(theirs.stdout)


def test_unknown_node_and_topic_errors_match(live_graph):
    uri, _ = live_graph
    for tool, args in (
        ("rosnode", ["info", "/nope"]),
        ("rostopic", ["info", "/nope"]),
        ("rosservice", ["type", "/nope"]),
    ):
        ours = run_tool(tool, args, uri, real=False)
        theirs = run_tool(tool, args, uri, real=True)
        assert ours.stdout == theirs.stdout
        assert ours.stderr.strip() == theirs.stderr.strip()
        assert "Traceback" not in ours.stderr


def test_seed_commands_work(live_graph):
    """The first seed's commands, as printed, against both masters."""
    uri, _ = live_graph
    ping = run_tool("rosnode", ["ping", "-c", "1", "/talker"], uri, real=False)
    assert ping.returncode == 0 and "xmlrpc reply from" in ping.stdout
    echo = run_tool("rostopic", ["echo", "-n", "2", "/chatter"], uri, real=False)
    assert echo.stdout.count("---") == 2 and 'data: "hello ' in echo.stdout
    ttype = run_tool("rostopic", ["type", "/chatter"], uri, real=False)
    assert ttype.stdout == "std_msgs/String\n"


def _rostopic_node_up(uri: str) -> bool:
    """True once a ``rostopic`` node has registered with the master (init_node registers its /rosout
    publisher). Debian's echo subscribes only once the topic has a publisher to take the type from,
    then polls for it every 0.1 s: well within ``pub -1``'s 3 s latch once it is up."""
    _, _, state = xmlrpc.client.ServerProxy(uri).getSystemState("/golden_test")
    return any("rostopic" in node for kind in state for _, nodes in kind for node in nodes)


def test_pub_reaches_real_echo(live_graph):
    """`rostopic pub -1 /turtle1/cmd_vel geometry_msgs/Twist '{linear: {x: 0.2}}'` as the seed prints it,
    received by Debian's real rostopic echo."""
    uri, _ = live_graph
    from graph_procs import ninjemys_env  # noqa: PLC0415

    from ninjemys.testing import ninjemys_bin, ros1_env

    echo = subprocess.Popen(
        ["/usr/bin/rostopic", "echo", "-n", "1", "/turtle1/cmd_vel"],
        env=ros1_env(uri),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        # `pub -1` latches for 3 s and exits: under load Debian's echo could still be starting by then
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not _rostopic_node_up(uri):
            time.sleep(0.1)
        pub = subprocess.run(
            [
                ninjemys_bin("rostopic"),
                "pub",
                "-1",
                "/turtle1/cmd_vel",
                "geometry_msgs/Twist",
                "{linear: {x: 0.2}}",
            ],
            env=ninjemys_env(uri),
            capture_output=True,
            text=True,
            timeout=20,
        )
        assert pub.returncode == 0, pub.stderr
        assert pub.stdout.startswith("publishing and latching message for 3 seconds")
        out, _ = echo.communicate(timeout=20)
    finally:
        if echo.poll() is None:
            echo.kill()
            echo.wait()
    assert "linear: \n  x: 0.2\n  y: 0.0\n  z: 0.0\nangular: \n  x: 0.0" in out
