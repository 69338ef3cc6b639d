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

import pytest

from ninjemys.drivers import rplidar_capsules as rc
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


class ModeInfo:
    """One scan mode as a device with firmware 1.24+ lists it over GET_LIDAR_CONF."""

    def __init__(self, ident: int, name: str, us_q8: int, max_distance_m: int, ans_type: int) -> None:
        self.id, self.name, self.us_q8, self.max_distance_m, self.ans_type = (
            ident,
            name,
            us_q8,
            max_distance_m,
            ans_type,
        )


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
        self.conf_queries: list[tuple[int, int]] = []
        self.working_mode = 0
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
            if cmd == rp.CMD_RESET:  # the core reboots and prints its banner, as an A1 does
                self._write(b"RP LIDAR System.\r\nFirmware Ver 1.29 - rtm, HW Ver 7\r\nModel: 18\r\n")
        elif cmd == rp.CMD_GET_INFO:
            info = rp.DeviceInfo(0x18, self.firmware[0] << 8 | self.firmware[1], 7, bytes(range(0xA0, 0xB0)))
            self._answer(rp.Descriptor(20, 0, rp.ANS_TYPE_DEVINFO), info.pack())
        elif cmd == rp.CMD_GET_HEALTH:
            self._answer(rp.Descriptor(3, 0, rp.ANS_TYPE_DEVHEALTH), rp.Health(*self.health).pack())
        elif cmd == rp.CMD_GET_SAMPLERATE:
            us = int(round(1e6 / self.samples_per_s))
            self._answer(rp.Descriptor(4, 0, rp.ANS_TYPE_SAMPLE_RATE), rp.struct.pack("<HH", 500, us))
        elif cmd == rp.CMD_GET_LIDAR_CONF:
            conf_type, mode_id = rp.struct.unpack_from("<IH", payload)
            self.conf_queries.append((conf_type, mode_id))
            data = rp.struct.pack("<I", conf_type) + self._conf(conf_type, mode_id)
            self._answer(rp.Descriptor(len(data), 0, rp.ANS_TYPE_GET_LIDAR_CONF), data)
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
            elif mode != rp.CMD_EXPRESS_SCAN:
                out = bytearray()
                per = self.capsule_samples(mode)
                while due >= per:
                    out += self.capsule(mode, k, first)
                    first = False
                    k += 1
                    due -= per
                    self.sent_samples += per
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

    def scan_modes(self) -> tuple[ModeInfo, ...]:
        """An A1's modes over GET_LIDAR_CONF (firmware 1.24 and later): Standard (2 kHz) and Express."""
        us = int(round(1e6 / self.samples_per_s))
        return (
            ModeInfo(0, "Standard", 500 << 8, 16, rp.ANS_TYPE_MEASUREMENT),
            ModeInfo(1, "Express", us << 8, 16, rp.ANS_TYPE_MEASUREMENT_CAPSULED),
        )

    typical_mode = 1

    def _conf(self, conf_type: int, mode_id: int) -> bytes:
        modes = self.scan_modes()
        if conf_type == rp.CONF_SCAN_MODE_COUNT:
            return rp.struct.pack("<H", len(modes))
        if conf_type == rp.CONF_SCAN_MODE_TYPICAL:
            return rp.struct.pack("<H", self.typical_mode)
        mode = modes[mode_id]
        if conf_type == rp.CONF_SCAN_MODE_US_PER_SAMPLE:
            return rp.struct.pack("<I", mode.us_q8)
        if conf_type == rp.CONF_SCAN_MODE_MAX_DISTANCE:
            return rp.struct.pack("<I", mode.max_distance_m << 8)
        if conf_type == rp.CONF_SCAN_MODE_ANS_TYPE:
            return bytes((mode.ans_type,))
        if conf_type == rp.CONF_SCAN_MODE_NAME:
            return mode.name.encode() + b"\0"
        raise AssertionError(f"GET_LIDAR_CONF entry 0x{conf_type:X} is not emulated")

    def capsule_samples(self, mode: int) -> int:
        """Samples per capsule of a stream other than Standard and Express (see EmulatedA3)."""
        raise AssertionError(f"the emulated A1 streams only SCAN and EXPRESS_SCAN, not {mode}")

    def capsule(self, mode: int, k: int, first: bool) -> bytes:
        raise AssertionError(f"the emulated A1 streams only SCAN and EXPRESS_SCAN, not {mode}")

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


#: an A3's modes (as Slamtec's firmware 1.2x lists them) plus a dense-capsule one (an A2M12's DenseBoost)
A3_MODES = (
    ModeInfo(0, "Standard", 250 << 8, 16, rp.ANS_TYPE_MEASUREMENT),
    ModeInfo(1, "Express", 125 << 8, 16, rp.ANS_TYPE_MEASUREMENT_CAPSULED),
    ModeInfo(2, "Boost", 16000, 25, rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA),
    ModeInfo(3, "Sensitivity", 16000, 25, rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA),
    ModeInfo(4, "Stability", 100 << 8, 25, rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA),
    ModeInfo(5, "DenseBoost", 100 << 8, 25, rp.ANS_TYPE_MEASUREMENT_DENSE_CAPSULED),
)
TYPICAL_A3_MODE = 3


class EmulatedA3(EmulatedA1):
    """An A3 (firmware 1.29, 256000 baud): GET_LIDAR_CONF lists :data:`A3_MODES`, Sensitivity is typical,
    EXPRESS_SCAN with a mode's id as working mode streams its ultra (or dense) capsules of the room.

    One revolution of capsules is built when a mode starts and sent again and again: 16 ultra capsules
    of 96 samples (22.5 degrees each) or 24 dense capsules of 40 (15 degrees). Each ultra sample's
    distance is the room's along the angle the decoder will give it (its interpolated angle less the
    protocol's distance-dependent compensation), found by fixed-point iteration, and
    :meth:`mode_samples` says what was sent: (angle as decoded, distance as decoded) per sample.
    ``corrupt_every``: every n-th capsule goes out with a flipped byte (a bad checksum).
    """

    def __init__(
        self,
        corrupt_every: int = 0,
        modes: tuple[ModeInfo, ...] = A3_MODES,
        bad_conf: bool = False,
        **kwargs,  # noqa: ANN003
    ) -> None:
        self.corrupt_every = corrupt_every
        self.modes = modes
        self.bad_conf = bad_conf  # GET_LIDAR_CONF answers echo the wrong entry type
        self.corrupted = 0
        self._revs: dict[int, tuple[list[bytes], list[bytes], list[tuple[float, float]]]] = {}
        kwargs.setdefault("firmware", (1, 29))
        super().__init__(**kwargs)

    # -- GET_LIDAR_CONF and the modes ----------------------------------------------------------------------

    def _command(self, cmd: int, payload: bytes) -> None:
        if cmd == rp.CMD_EXPRESS_SCAN and payload[0] not in (0, 1):
            with self.cond:
                self.commands.append(cmd)
                self.cond.notify_all()
            mode = self.modes[payload[0]]
            size = rp.ULTRA_CAPSULE_SIZE if mode.ans_type == rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA else 84
            self.samples_per_s = 256e6 / mode.us_q8
            self._answer(rp.Descriptor(size, 1, mode.ans_type))
            self.working_mode = mode.id
            self.mode = mode.ans_type
            return
        if cmd in (rp.CMD_SCAN, rp.CMD_EXPRESS_SCAN):
            self.samples_per_s = 256e6 / self.modes[0 if cmd == rp.CMD_SCAN else 1].us_q8
        if cmd == rp.CMD_GET_LIDAR_CONF and self.bad_conf:
            conf_type = rp.struct.unpack_from("<I", payload)[0]
            data = rp.struct.pack("<I", conf_type + 1) + b"\x00\x00"
            self._answer(rp.Descriptor(len(data), 0, rp.ANS_TYPE_GET_LIDAR_CONF), data)
            return
        super()._command(cmd, payload)

    typical_mode = TYPICAL_A3_MODE

    def scan_modes(self) -> tuple[ModeInfo, ...]:
        return self.modes

    # -- the capsule streams -------------------------------------------------------------------------------

    def capsule_samples(self, mode: int) -> int:
        return rc.ULTRA_SAMPLES if mode == rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA else rc.DENSE_SAMPLES

    def capsule(self, mode: int, k: int, first: bool) -> bytes:
        plain, flagged, _ = self._revolution(mode)
        cap = (flagged if first else plain)[k % len(plain)]
        if self.corrupt_every and k % self.corrupt_every == self.corrupt_every - 1:
            self.corrupted += 1
            cap = cap[:20] + bytes((cap[20] ^ 0x5A,)) + cap[21:]
        if k % len(plain) == 0 and not first:
            self.rev_marks.append(time.time())
        return cap

    def mode_samples(self, mode: int) -> list[tuple[float, float]]:
        """(angle deg as the protocol decodes it, distance mm as sent) of one revolution of ``mode``."""
        return self._revolution(mode)[2]

    def _revolution(self, mode: int) -> tuple[list[bytes], list[bytes], list[tuple[float, float]]]:
        if mode not in self._revs:
            if mode == rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA:
                self._revs[mode] = self._ultra_revolution()
            else:
                self._revs[mode] = self._dense_revolution()
        return self._revs[mode]

    def _dense_revolution(self) -> tuple[list[bytes], list[bytes], list[tuple[float, float]]]:
        caps, step = 24, 15.0
        plain, flagged, samples = [], [], []
        for c in range(caps):
            angles = [c * step + i * step / rc.DENSE_SAMPLES for i in range(rc.DENSE_SAMPLES)]
            dists = [
                self._drop(c * rc.DENSE_SAMPLES + i, int(device_range_mm(a))) for i, a in enumerate(angles)
            ]
            plain.append(rc.pack_dense_capsule(c * step, dists, False))
            flagged.append(rc.pack_dense_capsule(c * step, dists, True))
            samples += zip(angles, map(float, dists), strict=True)
        return plain, flagged, samples

    def _ultra_revolution(self) -> tuple[list[bytes], list[bytes], list[tuple[float, float]]]:
        caps, step = 16, 22.5
        n = rc.ULTRA_SAMPLES
        wanted: list[list[int]] = []
        for c in range(caps):
            row = []
            for i in range(n):
                interp = c * step + i * step / n
                d = device_range_mm(interp - 7.0)
                for _ in range(4):  # the angle it lands at depends (weakly) on the distance itself
                    d = device_range_mm(interp - rc.ultra_offset_deg(int(round(d))))
                row.append(self._drop(c * n + i, int(round(d))))
            wanted.append(row)
        plain, flagged, samples = [], [], []
        for c in range(caps):
            next_major = rc.varbitscale_encode(wanted[(c + 1) % caps][0])
            cabins, sent = rc.pack_ultra_cabins(wanted[c], next_major)
            plain.append(rc.pack_ultra_capsule(c * step, cabins, False))
            flagged.append(rc.pack_ultra_capsule(c * step, cabins, True))
            for i, d in enumerate(sent):
                raw_q16 = int(round((c * step + i * step / n) * 64)) << 10
                angle = raw_q16 - int(round(rc.ultra_offset_deg(d) * 65536))
                samples.append((((angle >> 10) % (360 << 6)) / 64.0, float(d)))
        return plain, flagged, samples

    def _drop(self, index: int, mm: int) -> int:
        return 0 if self.drop_every and index % self.drop_every == 5 else mm


def check_room(scan, samples: list[tuple[float, float]], multiple: int = 1) -> None:  # noqa: ANN001
    """Every beam of a compensated scan against the emulator's samples: rplidar_ros' compensation puts
    each sample (in angle order) into the ``multiple`` bins of 1/multiple degree from its own, the later
    one winning (angles as the SDK hands them on: 1/64 degree made q14), and publishes bin b of n at laser angle pi - 359 b / (n - 1) degrees (for one bin a
    degree: pi - b); the range there is the room's along the winning sample's angle, within 1 cm."""
    count = 360 * multiple
    assert len(scan.ranges) == count
    winner: dict[int, float] = {}
    for a_q6, d in sorted(samples):
        a = rp.q14_degrees(int(round(a_q6 * 64)))  # what rplidar_ros reads (see q14_degrees)
        if d:
            for j in range(multiple):
                winner[min(int(a * multiple) + j, count - 1)] = a
    checked = 0
    for j, r in enumerate(scan.ranges):
        phi = scan.angle_min + j * scan.angle_increment
        device_bin = count - 1 - j
        if device_bin not in winner:
            assert math.isinf(r), (j, r)
            continue
        a = winner[device_bin]
        # rplidar_ros spreads the bins evenly over [pi - 359 deg, pi] whatever their count
        assert phi == pytest.approx(math.pi - math.radians(359.0 * device_bin / (count - 1)), abs=1e-6)
        assert abs(r - room_range(math.pi - math.radians(a))) < 0.01, (j, r, a)
        checked += 1
    assert checked > 0.8 * count
