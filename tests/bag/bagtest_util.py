"""Helpers shared by the bag tests: std_msgs/String bytes, writing sample bags, running real rosbag."""

from __future__ import annotations

import json
import struct
import subprocess
from pathlib import Path

from ninjemys.bag.writer import BagWriter
from ninjemys.testing import ROS1_PYTHON

STRING_HEADER = {
    "type": b"std_msgs/String",
    "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
    "message_definition": b"string data\n",
}
BASE = 1_700_000_000 * 10**9


def string_bytes(text: str) -> bytes:
    raw = text.encode()
    return struct.pack("<I", len(raw)) + raw


def write_sample(
    path: Path, compression: str = "none", count: int = 300, chunk_threshold: int = 4000
) -> list:
    """A bag with two topics interleaved; returns [(topic, ns, bytes)] in time order."""
    expected = []
    with BagWriter(path, compression=compression, chunk_threshold=chunk_threshold) as w:
        a = w.connection("/chatter", STRING_HEADER)
        b = w.connection("/other", dict(STRING_HEADER, callerid=b"/talker", latching=b"1"))
        for i in range(count):
            topic, conn = ("/other", b) if i % 3 == 0 else ("/chatter", a)
            ns = BASE + i * 10_000_000
            data = string_bytes(f"message {i}")
            w.write(conn, ns, data)
            expected.append((topic, ns, data))
    return expected


def ros1_run(code: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([ROS1_PYTHON, "-c", code, *args], capture_output=True, text=True, timeout=60)


READ_WITH_ROSBAG = """
import json, sys, rosbag
out = []
with rosbag.Bag(sys.argv[1]) as b:
    for topic, (dt, data, md5, pos, pytype), t in b.read_messages(raw=True):
        out.append([topic, t.to_nsec(), data.hex(), dt, md5])
print(json.dumps(out))
"""


def read_with_real_rosbag(path: Path) -> list:
    proc = ros1_run(READ_WITH_ROSBAG, str(path))
    assert proc.returncode == 0, proc.stderr
    return [(t, ns, bytes.fromhex(h)) for t, ns, h, _dt, _md5 in json.loads(proc.stdout)]
