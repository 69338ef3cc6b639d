"""rosserial_python's serial_node.py at 115200 baud: messages per second and round-trip latency against
what the baud rate allows.

A device of this benchmark's own (the rosserial protocol from ninjemys.drivers.rosserial_protocol) sits on
a pty and paces what it writes at 115200 baud (10 bits a byte on the wire: 11,520 bytes/s), and waits a
received packet's wire time before acting on it, so the link behaves as a real UART would. Printed:

* device -> ROS: std_msgs/Float32 packets (12 bytes) sent back to back; messages/s reaching a
  subscriber in another process, against the link's limit (960/s);
* ROS -> device -> ROS: a geometry_msgs/Twist on /cmd_vel that the device echoes on /echo; round-trip
  median and p95 against the wire time of the two packets (2 x 56 bytes = 9.7 ms).

Debian ships no rosserial, so the reference is the baud rate's limit.
Run alone: ``.venv/bin/python bench/drivers_rosserial.py [seconds]``.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import threading
import time
import tty

from ninjemys.drivers import rosserial_protocol as proto
from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.testing import run_master

BAUD = 115200
BYTES_PER_S = BAUD / 10.0
TopicInfo = get_message_class("rosserial_msgs/TopicInfo")
Float32 = get_message_class("std_msgs/Float32")
Twist = get_message_class("geometry_msgs/Twist")
Time = get_message_class("std_msgs/Time")
PUB_WL, PUB_ECHO, SUB_CMD = 125, 126, 100


class PacedDevice:
    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self.reader = proto.FrameReader()
        self.lock = threading.Lock()
        self.wire_free = time.monotonic()  # when the UART finishes what it was given
        self.configured = threading.Event()
        self.flood = False
        self.sent = 0
        self.stop = threading.Event()
        threading.Thread(target=self._rx, daemon=True).start()
        threading.Thread(target=self._tx, daemon=True).start()

    def send(self, topic_id: int, payload: bytes) -> None:
        data = proto.frame(topic_id, payload)
        with self.lock:
            now = time.monotonic()
            # the packet is complete at the far end once its last bit is on the wire
            done = max(now, self.wire_free) + len(data) / BYTES_PER_S
            self.wire_free = done
            time.sleep(done - now)
            os.write(self.master, data)

    def _info(self, topic: int, kind: int, name: str, cls: type) -> None:
        ti = TopicInfo()
        ti.topic_id, ti.topic_name, ti.message_type, ti.md5sum, ti.buffer_size = (
            topic,
            name,
            cls._type,
            cls._md5sum,
            512,
        )  # type: ignore[attr-defined]
        self.send(kind, ti.serialize_to_bytes())

    def _rx(self) -> None:
        while not self.stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.1)
            if not ready:
                continue
            try:
                data = os.read(self.master, 4096)
            except OSError:
                continue
            for f in self.reader.feed(data):
                if not isinstance(f, proto.Frame):
                    continue
                time.sleep((len(f.payload) + 8) / BYTES_PER_S)  # the packet's time on the wire
                if f.topic_id == proto.ID_PUBLISHER:
                    self._info(PUB_WL, proto.ID_PUBLISHER, "wl", Float32)
                    self._info(PUB_ECHO, proto.ID_PUBLISHER, "echo", Twist)
                    self._info(SUB_CMD, proto.ID_SUBSCRIBER, "cmd_vel", Twist)
                    self.send(proto.ID_TIME, Time().serialize_to_bytes())
                    self.configured.set()
                elif f.topic_id == SUB_CMD:
                    self.send(PUB_ECHO, f.payload)

    def _tx(self) -> None:
        """Flood: as many packets as the baud rate has let through since the flood began, every 5 ms."""
        packet = proto.frame(PUB_WL, Float32(data=1.5).serialize_to_bytes())
        sync = proto.frame(proto.ID_TIME, Time().serialize_to_bytes())
        began: float | None = None
        wire_bytes = 0
        last_sync = time.monotonic()
        while not self.stop.is_set():
            if not self.flood:
                began = None
                time.sleep(0.05)
                continue
            now = time.monotonic()
            if began is None:
                began, wire_bytes = now, 0
            n = int((now - began) * BYTES_PER_S - wire_bytes) // len(packet)
            if n > 0:
                burst = packet * n
                if now - last_sync > 1.0:  # the sketch's time sync, once a second, in the same budget
                    last_sync = now
                    burst = burst[: -len(packet)] + sync
                    n -= 1
                with self.lock:
                    os.write(self.master, burst)
                    self.wire_free = now
                wire_bytes += len(burst)
                self.sent += n
            time.sleep(0.005)


def main() -> None:
    window = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    dev = PacedDevice()
    with run_master() as uri:
        env = dict(os.environ, ROS_MASTER_URI=uri)
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "ninjemys.packages.run_shipped",
                "rosserial_python",
                "serial_node.py",
                f"_port:={dev.path}",
                f"_baud:={BAUD}",
            ],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        node = Node("bench_rosserial", master_uri=uri)
        count = [0]
        echoes: list[float] = []
        got = threading.Event()

        def on_wl(_m) -> None:  # noqa: ANN001
            count[0] += 1

        def on_echo(_m) -> None:  # noqa: ANN001
            got.set()

        node.subscriber("/wl", Float32, on_wl)
        node.subscriber("/echo", Twist, on_echo)
        pub = node.publisher("/cmd_vel", Twist)
        try:
            if not dev.configured.wait(30):
                raise SystemExit("the host did not ask for topics within 30 s")
            time.sleep(2.0)  # connections settle
            dev.flood = True
            time.sleep(1.0)
            c0, t0, s0 = count[0], time.monotonic(), dev.sent
            time.sleep(window)
            c1, t1, s1 = count[0], time.monotonic(), dev.sent
            dev.flood = False
            time.sleep(0.5)
            deadline = time.monotonic() + window
            while time.monotonic() < deadline and len(echoes) < 300:
                got.clear()
                t = time.perf_counter()
                pub.publish(Twist())
                if got.wait(2.0):
                    echoes.append(time.perf_counter() - t)
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(20)
            node.shutdown()
            dev.stop.set()
    rate = (c1 - c0) / (t1 - t0)
    sent = (s1 - s0) / (t1 - t0)
    limit = BYTES_PER_S / 12
    echoes.sort()
    floor = 2 * 56 / BYTES_PER_S
    load = os.getloadavg()
    print(f"rosserial at {BAUD} baud (pty paced as a UART)")
    print(
        f"  device -> ROS, std_msgs/Float32: {rate:.0f} msgs/s; the link's limit {limit:.0f}/s: {rate / limit:.2f} of it "
        f"(the paced device wrote {sent:.0f}/s: the host delivered {rate / max(sent, 1e-9):.2f} of that)"
    )
    if echoes:
        med, p95 = echoes[len(echoes) // 2], echoes[int(len(echoes) * 0.95)]
        print(
            f"  ROS -> device -> ROS, geometry_msgs/Twist: median {1000 * med:.1f} ms, p95 {1000 * p95:.1f} ms over "
            f"{len(echoes)} round trips; wire time {1000 * floor:.1f} ms: {med / floor:.2f} x"
        )
    print(f"  load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")


if __name__ == "__main__":
    main()
