"""An emulated RPLIDAR A1 on a pseudo-terminal, written from Slamtec's protocol document.

It answers GET_INFO, GET_HEALTH, GET_SAMPLERATE and GET_ACC_BOARD_FLAG, obeys STOP, RESET and
SET_MOTOR_PWM (recording each command it sees), and streams SCAN measurements or EXPRESS_SCAN capsules of
a known rectangular room at a chosen sample rate. The room is described in the laser frame that
rplidar_ros publishes (x forward for ROS, angles counter-clockwise), and the device measures at its own
clockwise angle ``a`` the ray at ``pi - a``: that is rplidar_ros' published convention, which the tests
check the node against.
"""

from __future__ import annotations

import math
import os
import select
import threading
import time
import tty

from ninjemys.drivers import rplidar_protocol as rp

#: the room, in the laser frame: x from -2.0 to 3.0 m, y from -1.5 to 2.5 m around the lidar
ROOM = (-2.0, 3.0, -1.5, 2.5)


def room_range(phi: float) -> float:
    """Metres from the lidar to the wall along laser-frame angle ``phi``."""
    x0, x1, y0, y1 = ROOM
    c, s = math.cos(phi), math.sin(phi)
    best = math.inf
    if c > 1e-12:
        best = min(best, x1 / c)
    elif c < -1e-12:
        best = min(best, x0 / c)
    if s > 1e-12:
        best = min(best, y1 / s)
    elif s < -1e-12:
        best = min(best, y0 / s)
    return best


def device_range_mm(angle_deg: float) -> float:
    return room_range(math.pi - math.radians(angle_deg)) * 1000.0


class EmulatedA1:
    def __init__(
        self,
        samples_per_s: float = 2000.0,
        firmware: tuple[int, int] = (1, 29),
        health: tuple[int, int] = (0, 0),
        bad_scan_descriptor: bool = False,
        drop_every: int = 37,
    ) -> None:
        self.samples_per_s = samples_per_s
        self.firmware = firmware
        self.health = health
        self.bad_scan_descriptor = bad_scan_descriptor
        self.drop_every = drop_every  # every n-th sample has no echo (distance 0)
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self.lock = threading.Lock()
        self.cond = threading.Condition()
        self.commands: list[int] = []
        self.pwm: list[int] = []
        self.mode: int | None = None  # CMD_SCAN or CMD_EXPRESS_SCAN while streaming
        self.sent_samples = 0
        self.rev_marks: list[float] = []  # wall time of writing each revolution-closing capsule (express)
        self._stop = threading.Event()
        self._rx = bytearray()
        self.std_angles = [(k + 0.3) for k in range(360)]  # one revolution of standard samples, degrees
        self.express_per_rev = 384  # 12 capsules of 32
        self.express_offset_q3 = 4  # every sample 0.5 degree before its interpolated angle
        self.threads = [
            threading.Thread(target=self._rx_loop, name="a1-rx", daemon=True),
            threading.Thread(target=self._tx_loop, name="a1-tx", daemon=True),
        ]
        for t in self.threads:
            t.start()

    # -- what the tests compare against ------------------------------------------------------------------

    def standard_samples(self) -> list[tuple[float, float]]:
        """(angle deg as transmitted, distance mm as transmitted) of one revolution."""
        out = []
        for k, a in enumerate(self.std_angles):
            q6 = round(a * 64) / 64
            d = 0.0 if self.drop_every and k % self.drop_every == 5 else round(device_range_mm(q6) * 4) / 4
            out.append((q6, d))
        return out

    def express_samples(self) -> list[tuple[float, float]]:
        step = 360.0 / self.express_per_rev
        out = []
        for k in range(self.express_per_rev):
            a = (k * step - self.express_offset_q3 / 8.0) % 360.0
            d = 0.0 if self.drop_every and k % self.drop_every == 5 else float(int(device_range_mm(a)))
            out.append((a, d))
        return out

    # -- the wire ------------------------------------------------------------------------------------------

    def _write(self, data: bytes) -> None:
        with self.lock:
            try:
                os.write(self.master, data)
            except OSError:
                pass

    def _answer(self, d: rp.Descriptor, payload: bytes = b"") -> None:
        self._write(d.pack() + payload)

    def _rx_loop(self) -> None:
        while not self._stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.1)
            if not ready:
                continue
            try:
                self._rx += os.read(self.master, 1024)
            except OSError:
                time.sleep(0.05)
                continue
            self._parse()

    def _parse(self) -> None:
        buf = self._rx
        while True:
            start = buf.find(rp.SYNC)
            if start < 0:
                buf.clear()
                return
            del buf[:start]
            if len(buf) < 2:
                return
            cmd = buf[1]
            if cmd & 0x80:
                if len(buf) < 3 or len(buf) < 4 + buf[2]:
                    return
                size = buf[2]
                payload = bytes(buf[3 : 3 + size])
                cs = 0
                for b in buf[: 3 + size]:
                    cs ^= b
                ok = cs == buf[3 + size]
                del buf[: 4 + size]
                if not ok:
                    continue
            else:
                payload = b""
                del buf[:2]
            self._command(cmd, payload)

    def _command(self, cmd: int, payload: bytes) -> None:
        with self.cond:
            self.commands.append(cmd)
            self.cond.notify_all()
        if cmd in (rp.CMD_STOP, rp.CMD_RESET):
            self.mode = None
        elif cmd == rp.CMD_GET_INFO:
            info = rp.DeviceInfo(0x18, self.firmware[0] << 8 | self.firmware[1], 7, bytes(range(0xA0, 0xB0)))
            self._answer(rp.Descriptor(20, 0, rp.ANS_TYPE_DEVINFO), info.pack())
        elif cmd == rp.CMD_GET_HEALTH:
            self._answer(rp.Descriptor(3, 0, rp.ANS_TYPE_DEVHEALTH), rp.Health(*self.health).pack())
        elif cmd == rp.CMD_GET_SAMPLERATE:
            us = int(round(1e6 / self.samples_per_s))
            self._answer(rp.Descriptor(4, 0, rp.ANS_TYPE_SAMPLE_RATE), rp.struct.pack("<HH", 500, us))
        elif cmd == rp.CMD_GET_ACC_BOARD_FLAG:
            self._answer(rp.Descriptor(4, 0, rp.ANS_TYPE_ACC_BOARD_FLAG), b"\x00\x00\x00\x00")
        elif cmd == rp.CMD_SET_MOTOR_PWM:
            with self.cond:
                self.pwm.append(rp.struct.unpack("<H", payload)[0])
        elif cmd == rp.CMD_SCAN:
            if self.bad_scan_descriptor:
                self._answer(rp.Descriptor(84, 1, 0x82))
                return
            self._answer(rp.Descriptor(5, 1, rp.ANS_TYPE_MEASUREMENT))
            self.mode = rp.CMD_SCAN
        elif cmd == rp.CMD_EXPRESS_SCAN:
            self._answer(rp.Descriptor(84, 1, rp.ANS_TYPE_MEASUREMENT_CAPSULED))
            self.mode = rp.CMD_EXPRESS_SCAN

    def _tx_loop(self) -> None:
        k = 0  # the next sample's index in the revolution
        first = True
        tick = 0.01
        due = 0.0
        last_mode = None
        last = time.monotonic()
        while not self._stop.wait(tick):
            now = time.monotonic()
            elapsed, last = min(now - last, 0.2), now  # the rate holds even when the wait oversleeps
            mode = self.mode
            if mode != last_mode:
                k, first, due, last_mode = 0, True, 0.0, mode
            if mode is None:
                continue
            due += self.samples_per_s * elapsed
            if mode == rp.CMD_SCAN:
                rev = self.standard_samples()
                out = bytearray()
                while due >= 1:
                    a, d = rev[k]
                    out += rp.pack_node(a, d, 47 if d else 0, start=(k == 0))
                    k = (k + 1) % len(rev)
                    due -= 1
                    self.sent_samples += 1
                self._write(bytes(out))
            else:
                rev = self.express_samples()
                out = bytearray()
                while due >= 32:
                    if k == 0 and not first:
                        self.rev_marks.append(time.time())  # it gives the last capsule its end angle
                    start_deg = k * 360.0 / self.express_per_rev
                    dists = [rev[(k + i) % len(rev)][1] for i in range(32)]
                    out += rp.pack_capsule(start_deg, dists, [self.express_offset_q3] * 32, start=first)
                    first = False
                    k = (k + 32) % len(rev)
                    due -= 32
                    self.sent_samples += 32
                self._write(bytes(out))

    def wait(self, pred, timeout: float = 20.0) -> None:  # noqa: ANN001
        with self.cond:
            if not self.cond.wait_for(pred, timeout):
                raise AssertionError("the emulated A1 did not see what was expected")

    def close(self) -> None:
        self._stop.set()
        for t in self.threads:
            t.join(2)
        os.close(self.master)
        os.close(self.slave)
