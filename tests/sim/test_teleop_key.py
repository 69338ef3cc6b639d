"""turtle_teleop_key through a pseudo-terminal: arrow keys -> Twist messages, 'q' exits cleanly."""

from __future__ import annotations

import os
import threading

import pexpect
import pytest

from geometry_msgs.msg import Twist
from ninjemys.sim.teleop_key import KeyDecoder
from ninjemys.testing import ninjemys_bin, wait_until

UP, DOWN, RIGHT, LEFT = "\x1b[A", "\x1b[B", "\x1b[C", "\x1b[D"


def test_key_decoder_handles_split_sequences() -> None:
    d = KeyDecoder()
    assert d.feed(b"\x1b[") == []
    assert d.feed(b"Ax\x1bOD") == ["UP", "LEFT"]
    assert d.feed(b"\x1b[Z q") == ["QUIT"]


@pytest.mark.parametrize("remap", [None, "turtle1/cmd_vel:=/robot/cmd_vel"])
def test_arrow_keys_publish_twists_and_q_quits(master: str, client, remap: str | None) -> None:  # type: ignore[no-untyped-def]
    topic = "/robot/cmd_vel" if remap else "/turtle1/cmd_vel"
    got: list[tuple[float, float]] = []
    lock = threading.Lock()

    def on_twist(msg: Twist) -> None:
        with lock:
            got.append((msg.linear.x, msg.angular.z))

    client.subscriber(topic, Twist, on_twist)
    env = dict(os.environ, ROS_MASTER_URI=master)
    args = [remap] if remap else []
    child = pexpect.spawn(ninjemys_bin("turtle_teleop_key"), args, env=env, encoding="utf-8", timeout=20)
    try:
        child.expect_exact("Reading from keyboard")
        child.expect_exact("Use arrow keys to move the turtle. 'q' to quit.")
        pub_ready = lambda: any(topic == t for t, _ in client.master.call("getSystemState")[0])  # noqa: E731
        wait_until(pub_ready, what="teleop to advertise")
        # the first message may race the connection set-up: press until one arrives, then the sequence
        wait_until(lambda: child.send(UP) and got, what="first Twist")
        expected = [(2.0, 0.0), (0.0, 2.0), (-2.0, 0.0), (0.0, -2.0)]
        for key in (UP, LEFT, DOWN, RIGHT):
            child.send(key)
        # one TCP connection keeps order: warm-up UPs, then exactly the four keys
        wait_until(lambda: got[-4:] == expected, what="the four Twists")
        assert all(t == (2.0, 0.0) for t in got[:-4])
        child.send("q")
        child.expect(pexpect.EOF)
        child.close()
        assert child.exitstatus == 0
        assert "Traceback" not in (child.before or "")
    finally:
        if child.isalive():
            child.terminate(force=True)


def test_q_restores_the_terminal(master: str) -> None:
    """After 'q' the shell's terminal is canonical and echoing again (stty shows icanon and echo)."""
    env = dict(os.environ, ROS_MASTER_URI=master, PS1="$ ")
    shell = pexpect.spawn("/bin/sh", ["-i"], env=env, encoding="utf-8", timeout=20)
    try:
        shell.expect_exact("$ ")
        shell.sendline(ninjemys_bin("turtle_teleop_key"))
        shell.expect_exact("'q' to quit.")
        shell.send("q")
        shell.expect_exact("$ ")
        shell.sendline("stty -a; echo status=$?")
        shell.expect(r"status=0")
        modes = shell.before.split()
        assert "icanon" in modes and "echo" in modes and "isig" in modes
    finally:
        shell.terminate(force=True)
