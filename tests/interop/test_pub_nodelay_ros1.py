"""Our publisher sets TCP_NODELAY whatever the subscriber's header says: a real rospy subscriber
(which asks for ``tcp_nodelay: 0`` by default) gets small messages without Nagle's delayed-ACK wait."""

from __future__ import annotations

import socket
import statistics
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

sys.path[:0] = [str(Path(__file__).parent), str(Path(__file__).parents[1] / "node")]

from node_harness import MasterProcess  # noqa: E402
from node_msgs import String  # noqa: E402
from ros1_peers import rospy  # noqa: E402

from ninjemys import testing  # noqa: E402
from ninjemys.node import Node  # noqa: E402
from ninjemys.testing import NodeProcess, wait_until  # noqa: E402

pytestmark = pytest.mark.ros1

# a default rospy.Subscriber (tcp_nodelay=False); prints how long each message took to arrive
_LATENCY_LISTENER = """
import time, rospy
from std_msgs.msg import String
rospy.init_node('rospy_latency')
def cb(m):
    seq, sent = m.data.split()
    print('lat %s %.6f' % (seq, time.time() - float(sent)), flush=True)
rospy.Subscriber('/status', String, cb)
print('ready', flush=True)
rospy.spin()
"""


@pytest.fixture
def master() -> Iterator[MasterProcess]:
    m = MasterProcess(testing.free_port())
    m.start()
    try:
        yield m
    finally:
        m.kill()


def test_small_messages_to_a_default_rospy_subscriber_skip_nagle(master) -> None:
    node = Node("status_pub", master_uri=master.uri)
    child: NodeProcess | None = None
    try:
        pub = node.publisher("status", String, queue_size=10)
        child = rospy(_LATENCY_LISTENER, master.uri)
        assert child.wait_for(lambda line: line == "ready", timeout=30), child.describe()
        assert wait_until(lambda: pub.get_num_connections() == 1, timeout=15), child.describe()
        # rospy's header asked for "tcp_nodelay: 0"; the option is ours to set, and it is set
        (conn,) = pub._pub.connections
        assert conn.sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) != 0
        # 10 Hz from the first tick, two small messages a tick (as an action server's feedback and
        # status): with Nagle the second may wait for the ACK of the first, which a receiver still in
        # its handshake's delayed-ACK ("pingpong") mode holds back ~40 ms
        seq = 0
        for _ in range(30):
            for _ in range(2):
                pub.publish(String(f"{seq} {time.time()!r}"))
                seq += 1
                time.sleep(0.002)
            time.sleep(0.1)
        assert wait_until(lambda: sum(line.startswith("lat ") for line in child.out) == seq, timeout=10), (
            child.describe()
        )
        latency = {
            int(s): float(t) for _, s, t in (line.split() for line in child.out if line.startswith("lat "))
        }
        seconds = [latency[i] for i in range(1, seq, 2)]
        assert statistics.median(seconds) < 0.005, sorted(seconds)
    finally:
        if child is not None:
            child.kill()
        node.shutdown("test over")
