"""record and play as nodes, against real ROS 1 nodes and ours (processes, free ports, torn down)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import pytest
from bagtest_util import BASE, STRING_HEADER, read_with_real_rosbag, string_bytes

from ninjemys.bag.play import stand_in_class
from ninjemys.bag.reader import BagReader
from ninjemys.bag.writer import BagWriter
from ninjemys.testing import ROS1_PYTHON, ninjemys_bin, ros1_env, run_master

String = stand_in_class("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1", "string data\n")


@pytest.fixture
def master():
    with run_master() as uri:
        yield uri


@pytest.fixture
def procs():
    started: list[subprocess.Popen] = []
    yield started
    for proc in started:
        if proc.poll() is None:
            proc.kill()
        proc.wait()


def our_env(uri):
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = uri
    return env


class RawPublisher:
    """An in-process ninjemys node publishing numbered std_msgs/String at ``hz`` on a thread."""

    def __init__(self, uri, topic, hz):
        from ninjemys.node import Node

        self.node = Node("numbers", anonymous=True, master_uri=uri)
        self.pub = self.node.publisher(topic, String, queue_size=2000)
        self.count = 0
        self.hz = hz
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        start = time.monotonic()
        while not self._stop.is_set():
            self.pub.publish_raw(string_bytes(str(self.count)))
            self.count += 1
            delay = start + self.count / self.hz - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)

    def close(self):
        self._stop.set()
        self.thread.join()
        self.node.shutdown("test over")


def wait_for_file(path, timeout=20.0):
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.05)


def wait_until_has_messages(path, minimum, timeout=20.0):
    deadline = time.monotonic() + timeout
    while True:
        if path.exists():
            try:
                with BagReader(path) as r:
                    if r.message_count >= minimum:
                        return
            except Exception:
                pass
        assert time.monotonic() < deadline, f"{path} did not reach {minimum} messages"
        time.sleep(0.1)


@pytest.mark.ros1
def test_record_real_and_ninjemys_publishers_together(tmp_path, master, procs):
    real = subprocess.Popen(
        ["/usr/bin/rostopic", "pub", "-r", "50", "/real", "std_msgs/String", "data: from ros1"],
        env=ros1_env(master),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    procs.append(real)
    ours = RawPublisher(master, "/ours", 50)
    try:
        rec = subprocess.Popen(
            [ninjemys_bin("rosbag"), "record", "-O", "both", "/real", "/ours"],
            cwd=tmp_path,
            env=our_env(master),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        procs.append(rec)
        wait_until_has_messages(tmp_path / "both.bag.active", 40)
        rec.send_signal(signal.SIGINT)
        out, err = rec.communicate(timeout=20)
        assert rec.returncode == 0, err
    finally:
        ours.close()
    assert "Recording to 'both.bag'." in out
    bag = tmp_path / "both.bag"
    assert bag.exists() and not (tmp_path / "both.bag.active").exists()
    with BagReader(bag) as r:
        assert r.indexed
        real_conn = r.topic_connections("/real")[0]
        ours_conn = r.topic_connections("/ours")[0]
        assert real_conn.callerid.startswith("/rostopic") and ours_conn.callerid.startswith("/numbers")
        assert real_conn.md5sum == ours_conn.md5sum == "992ce8a1687cec8c8bd883ec73ca41d1"
        assert real_conn.msg_def.strip() == "string data"
        data = {m.connection.topic: bytes(m.data) for m in r.read()}
        assert data["/real"] == string_bytes("from ros1")
    got = read_with_real_rosbag(bag)
    assert {t for t, _, _ in got} == {"/real", "/ours"}


@pytest.mark.ros1
def test_play_into_rospy_with_sim_time(tmp_path, master, procs):
    bag = tmp_path / "sim.bag"
    with BagWriter(bag) as w:
        c = w.connection("/chatter", STRING_HEADER)
        for i in range(60):
            w.write(c, BASE + i * 50_000_000, string_bytes(f"sim {i}"))
    listener_code = """
import rospy
from std_msgs.msg import String
rospy.init_node('simlistener')
assert rospy.get_param('/use_sim_time') is True
got = []
def cb(msg):
    got.append((msg.data, rospy.get_rostime().to_nsec()))
    if len(got) == 5:
        rospy.signal_shutdown('enough')
rospy.Subscriber('/chatter', String, cb)
print('READY', flush=True)
rospy.spin()
for data, ns in got:
    print(data, ns, flush=True)
"""
    setter = subprocess.run(
        ["/usr/bin/rosparam", "set", "/use_sim_time", "true"],
        env=ros1_env(master),
        capture_output=True,
        timeout=30,
    )
    assert setter.returncode == 0, setter.stderr
    listener = subprocess.Popen(
        [ROS1_PYTHON, "-c", listener_code],
        env=ros1_env(master),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    procs.append(listener)
    assert listener.stdout.readline().strip() == "READY"
    player = subprocess.Popen(
        [ninjemys_bin("rosbag"), "play", "--clock", "-d", "1.5", "-q", str(bag)],
        env=our_env(master),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    procs.append(player)
    out, err = listener.communicate(timeout=40)
    assert listener.returncode == 0, err
    player.wait(timeout=30)
    assert player.returncode == 0, player.stderr.read()
    lines = [line.split() for line in out.strip().splitlines()]
    assert len(lines) == 5
    for _sim, text_i, ns in lines:
        i = int(text_i)
        # the listener's clock is the bag's: 2023 stamps, near the message's own time
        assert BASE <= int(ns) <= BASE + 60 * 50_000_000
        assert abs(int(ns) - (BASE + i * 50_000_000)) < 200_000_000


def test_sigkill_during_1khz_recording_then_reindex(tmp_path, master, procs):
    pub = RawPublisher(master, "/fast", 1000)
    try:
        rec = subprocess.Popen(
            [ninjemys_bin("rosbag"), "record", "-q", "-O", "crash", "/fast"],
            cwd=tmp_path,
            env=our_env(master),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        procs.append(rec)
        active = tmp_path / "crash.bag.active"
        wait_until_has_messages(active, 500)
        with BagReader(active) as r:
            on_disk_before = r.message_count
        time.sleep(1.5)  # the writer must put a new chunk on disk at least once a second
        with BagReader(active) as r:
            on_disk_at_kill = r.message_count
        rec.kill()
        rec.wait()
    finally:
        pub.close()
    assert on_disk_at_kill > on_disk_before
    with BagReader(active) as r:
        direct = [bytes(m.data) for m in r.read()]
    proc = subprocess.run(
        [ninjemys_bin("rosbag"), "reindex", "-q", str(active)], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr
    with BagReader(active) as r:
        assert r.indexed
        recovered = [bytes(m.data) for m in r.read()]
    assert recovered == direct
    numbers = [int(d[4:]) for d in recovered]
    # everything flushed before the kill survives it, as one gap-free run of the publisher's numbers
    assert len(numbers) >= on_disk_at_kill
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))


def test_limit_stops_recording_by_itself(tmp_path, master, procs):
    pub = RawPublisher(master, "/lim", 100)
    try:
        rec = subprocess.run(
            [ninjemys_bin("rosbag"), "record", "-l", "7", "-O", "lim", "/lim"],
            cwd=tmp_path,
            env=our_env(master),
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        pub.close()
    assert rec.returncode == 0, rec.stderr
    with BagReader(tmp_path / "lim.bag") as r:
        assert r.message_count == 7


def test_record_without_topics_is_one_line_error(tmp_path):
    proc = subprocess.run(
        [ninjemys_bin("rosbag"), "record"], capture_output=True, text=True, timeout=30, cwd=tmp_path
    )
    assert proc.returncode != 0 and "ERROR" in proc.stderr and "Traceback" not in proc.stderr


if __name__ == "__main__":
    sys.exit(pytest.main([__file__]))
