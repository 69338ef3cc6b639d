"""The subscriber's receive path (issue 25): CPU per received message, ours beside rospy's.

Run: ``.venv/bin/python bench/node_receive.py [seconds]``. Two parts:

* in this process, the two receive paths of this tree on the same received chunks: ``fused`` (one
  generated loop cuts and decodes the frames, :mod:`ninjemys.idl.framedecode`) and ``per-frame``
  (``FrameReader.commit`` then ``deserialize_from`` per frame); microseconds per message, a trivial
  callback included, for a 16-byte ``std_msgs/String`` and a 20-joint ``sensor_msgs/JointState``;
* between processes, one ninjemys publisher floods 16-byte Strings (``queue_size=None``) to a sink
  that is ninjemys, then rospy, on one CPU and across two: messages per second delivered and the
  sink's CPU time per message received (user + system, all its threads, from /proc, from the moment
  it is subscribed until it reports).

The publisher is the same for both sinks, so the rates say what the publisher and the kernel allow;
the CPU per message is the receive side's own cost.
"""

from __future__ import annotations

import os
import struct
import sys
import time

from ninjemys.idl.framedecode import frames_decoder
from ninjemys.idl.loader import get_message_class
from ninjemys.wire.tcpros import FrameReader
from node_common import CROSS_CPU, IMPLS, OURS, SAME_CPU, Role, header, master, ratio, roles


def _chunks(body: bytes, count: int, size: int = 1 << 16) -> list[bytes]:
    """``count`` frames of ``body`` as a socket would hand them over: ``size`` bytes at a time."""
    stream = (struct.pack("<I", len(body)) + body) * count
    return [stream[i : i + size] for i in range(0, len(stream), size)]


def _feed(reader: FrameReader, chunk: bytes):  # type: ignore[no-untyped-def]
    """Copy ``chunk`` into the reader's buffer as ``recv_into`` would, yielding each count copied."""
    pos = 0
    while pos < len(chunk):
        buf = reader.buffer()
        n = min(len(buf), len(chunk) - pos)
        buf[:n] = chunk[pos : pos + n]
        pos += n
        yield n


def _per_frame(cls: type, chunks: list[bytes]) -> int:
    reader, decode, got = FrameReader(), cls.deserialize_from, [0]  # type: ignore[attr-defined]

    def callback(msg: object) -> None:
        got[0] += 1

    for chunk in chunks:
        for n in _feed(reader, chunk):
            for frame in reader.commit(n):
                callback(decode(frame))
    return got[0]


def _fused(cls: type, chunks: list[bytes]) -> int:
    reader, got = FrameReader(), [0]
    decode = frames_decoder(cls)[0]  # type: ignore[index]

    def callback(msg: object) -> None:
        got[0] += 1

    for chunk in chunks:
        for n in _feed(reader, chunk):
            out: list[object] = []
            bad: list[object] = []
            reader.commit_decoded(n, decode, out, bad)
            for msg in out:
                callback(msg)
    return got[0]


def _best_us(fn, cls: type, chunks: list[bytes], count: int) -> float:
    best = float("inf")
    for _ in range(5):
        start = time.process_time()
        assert fn(cls, chunks) == count
        best = min(best, time.process_time() - start)
    return best / count * 1e6


def in_process() -> None:
    string = get_message_class("std_msgs/String")
    joints = get_message_class("sensor_msgs/JointState")
    js = joints()
    js.name = [f"joint_{i}" for i in range(20)]
    js.position, js.velocity, js.effort = [0.5] * 20, [0.1] * 20, [0.0] * 20
    for cls, body, count in ((string, string("x" * 16).serialize_to_bytes(), 200_000),
                             (joints, js.serialize_to_bytes(), 50_000)):  # fmt: skip
        chunks = _chunks(body, count)
        old = _best_us(_per_frame, cls, chunks, count)
        new = _best_us(_fused, cls, chunks, count)
        name = cls._type  # type: ignore[attr-defined]
        print(
            f"in-process {name:22s} per-frame {old:6.2f} us/msg   fused {new:6.2f} us/msg   {ratio(new, old)}"
        )


def _cpu(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def between(uri: str, impl: str, cpus: tuple[str, str], seconds: str) -> tuple[float, float]:
    """Delivered rate, and the sink's CPU microseconds per message received: its CPU time from
    "ready" (subscribed, idle) to its result, over the messages it received (set-up costs included,
    the same for both)."""
    sink = Role(impl, uri, "sink", cpu=cpus[1])
    with roles(sink):
        sink.ready()
        cpu0 = _cpu(sink.proc.pid)
        flood = Role(OURS, uri, "flood", "None", seconds, cpu=cpus[0])
        with roles(flood):
            flood.result()
            got = sink.result()
            cpu1 = _cpu(sink.proc.pid)
    return got["rate"], (cpu1 - cpu0) / max(got["received"], 1) * 1e6


def main() -> None:
    seconds = sys.argv[1] if len(sys.argv) > 1 else "4"
    header("receive path: CPU per received message")
    in_process()
    with master() as uri:
        for place, cpus in (("across CPUs", CROSS_CPU), ("same CPU", SAME_CPU)):
            results = {impl: between(uri, impl, cpus, seconds) for impl in IMPLS}
            for impl, (rate, us) in results.items():
                print(f"{place:11s} sink {impl:9s} {rate / 1e3:8.1f} k msgs/s   {us:6.2f} us CPU/msg")
            if len(results) > 1:
                print(f"{place:11s} CPU per message ratio {ratio(results[OURS][1], results['rospy'][1])}")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
