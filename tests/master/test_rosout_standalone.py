"""`rosrun rosout rosout`: rosout as its own process republishes /rosout on /rosout_agg and logs it."""

from __future__ import annotations

import os
import signal
import subprocess
import threading

from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.testing import ninjemys_bin


def test_rosrun_rosout_relays_and_logs(tmp_path) -> None:
    log_class = get_message_class("rosgraph_msgs/Log")
    with MasterThread() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_LOG_DIR=str(tmp_path), PYTHONUNBUFFERED="1")
        proc = subprocess.Popen(
            [ninjemys_bin("rosrun"), "rosout", "rosout"],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        node = Node("log_probe", master_uri=uri)
        try:
            got: list[str] = []
            arrived = threading.Event()
            node.subscriber("/rosout_agg", log_class, lambda m: (got.append(m.msg), arrived.set()))
            pub = node.publisher("/rosout", log_class, queue_size=None)
            # /rosout_agg is not latched: publish until both hops are connected and one comes back
            for _ in range(100):
                pub.publish(log_class(level=log_class.INFO, name="/log_probe", msg="hello rosout"))
                if arrived.wait(0.2):
                    break
            assert arrived.is_set(), "nothing came back on /rosout_agg"
            assert set(got) == {"hello rosout"}
            proc.send_signal(signal.SIGINT)
            assert proc.wait(10) == 0
            logs = list(tmp_path.rglob("rosout.log"))
            assert logs and "hello rosout" in logs[0].read_text()
        finally:
            node.shutdown()
            if proc.poll() is None:
                proc.kill()
                proc.wait()
