"""SIGTERM (``kill``, ``timeout 10 rostopic hz /scan``) stops a tool as Ctrl-C does: exit 0 and its
node gone from the master, as Debian's rostopic (rospy handles SIGTERM); ours vanished and left
``/rostopic_<pid>_<stamp>`` in ``rosnode list`` for good."""

from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

from ninjemys.master.client import MasterClient
from ninjemys.testing import kill_tree, ninjemys_bin, run_master


def _rostopic_nodes(uri: str) -> list[str]:
    client = MasterClient(uri, "/sigterm_probe")
    publishers, subscribers, _ = client.get_system_state()
    return sorted(
        {n for _, nodes in (*publishers, *subscribers) for n in nodes if n.startswith("/rostopic_")}
    )


@pytest.mark.parametrize("argv", [["hz", "/rosout"], ["echo", "/rosout"]], ids=["hz", "echo"])
def test_a_terminated_rostopic_unregisters_its_node(argv: list[str], tmp_path) -> None:  # noqa: ANN001
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=str(tmp_path))
        proc = subprocess.Popen(
            [ninjemys_bin("rostopic"), *argv], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
        )
        try:
            deadline = time.monotonic() + 30
            while not _rostopic_nodes(uri):
                assert time.monotonic() < deadline, "rostopic never registered"
                assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else ""
                time.sleep(0.1)
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(20) == 0
            assert _rostopic_nodes(uri) == []
            assert b"Traceback" not in (proc.stderr.read() if proc.stderr else b"")
        finally:
            if proc.poll() is None:
                kill_tree(proc)
