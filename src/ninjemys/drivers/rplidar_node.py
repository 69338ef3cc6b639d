"""``rosrun rplidar_ros rplidarNode``: a Slamtec RPLIDAR on ``sensor_msgs/LaserScan``, as rplidar_ros 1.10.

Parameters (private): ``serial_port`` (/dev/ttyUSB0), ``serial_baudrate`` (115200; A3: 256000),
``frame_id`` (laser_frame), ``inverted`` (false), ``scan_frequency`` (rplidar_ros 2.x: 10 Hz, the turn rate the
compensation bins are sized for), ``angle_compensate`` (false; the launch files set
true), ``scan_mode`` ("" = the device's typical mode; before firmware 1.24: Express when the firmware has it,
else Standard).
Publishes ``scan`` (queue 1000, as rplidar_ros); services ``stop_motor`` and ``start_motor``
(std_srvs/Empty). Start-up follows rplidar_ros: device info (S/N, firmware, hardware), health (an
error status stops the node with rplidar_ros' message), motor on, scan; each step's failure is one
clear line. Scan modes: a device with firmware 1.24 or later (A2M12, A3, S1) lists its own over
GET_LIDAR_CONF (name, microseconds per sample, range, answer type) and names its typical one (the mode
used when ``scan_mode`` is empty; Sensitivity on an A3); older ones have the legacy Standard and
Express. Standard, Express, dense-capsule and ultra-capsule modes are decoded; a mode the device does
not list is refused with rplidar_ros' list of supported modes. Capsules that fail their sync or
checksum are dropped, with one warning line a second at most saying how many bytes went.

The node owns the port: the services hand their work to the read loop, which does it between reads.
"""

from __future__ import annotations

import queue
import threading
import time
from typing import Any

from ninjemys.drivers import rplidar_capsules as rc
from ninjemys.drivers import rplidar_protocol as rp
from ninjemys.drivers.rplidar_scan import RevolutionAssembler, compensate_multiple, revolution_to_scan
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node.run import run_node

SDK_VERSION = "1.12.0"
#: legacy scan modes' range (the SDK's value when the device cannot be asked)
LEGACY_MAX_DISTANCE = 16.0
READ_TIMEOUT = 0.05
ANSWER_TIMEOUT = 1.0
#: reads of a scan stream wait until this much is there, or BATCH_WAIT has passed (CPU per sample)
BATCH_BYTES = 4 * rp.CAPSULE_SIZE
BATCH_WAIT = 0.01


#: how each measurement stream is decoded, by answer type
DECODERS: dict[int, Any] = {
    rp.ANS_TYPE_MEASUREMENT: rp.NodeDecoder,
    rp.ANS_TYPE_MEASUREMENT_CAPSULED: rp.CapsuleDecoder,
    rp.ANS_TYPE_MEASUREMENT_DENSE_CAPSULED: lambda: rp.CapsuleDecoder(rp.CAPSULE_SIZE, rc.dense_samples),
    rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA: lambda: rp.CapsuleDecoder(
        rp.ULTRA_CAPSULE_SIZE, rc.ultra_samples
    ),
}
#: a second between "bad capsule data" lines
BAD_DATA_LOG_INTERVAL = 1.0
#: seconds rplidar_ros 2.x waits for the device to answer again after initial_reset
RESET_TIMEOUT = 15.0
#: the SDK's RESULT_OPERATION_FAIL, as rplidar_ros prints it when the scan mode asked for is not there
RESULT_OPERATION_FAIL = 0x80008001


class ScanMode:
    def __init__(
        self,
        ident: int,
        name: str,
        us_per_sample: float,
        max_distance: float,
        ans_type: int,
    ) -> None:
        self.id = ident
        self.name = name
        self.us_per_sample = us_per_sample
        self.max_distance = max_distance
        self.ans_type = ans_type

    @property
    def cmd(self) -> int:
        """The request that starts it: SCAN for Standard, else EXPRESS_SCAN."""
        return rp.CMD_SCAN if self.id == rp.SCAN_MODE_STANDARD else rp.CMD_EXPRESS_SCAN

    @property
    def working_mode(self) -> int:
        """EXPRESS_SCAN's working mode byte: 0 for the legacy Express, else the mode's id."""
        return 0 if self.id == rp.SCAN_MODE_EXPRESS else self.id


class RplidarDevice:
    """Requests and answers on an open port (pyserial-like: ``read(n)`` with a timeout, ``write``)."""

    def __init__(self, port: Any) -> None:
        self.port = port
        self.motor_ctrl = False

    def _read_exact(self, size: int, timeout: float) -> bytes:
        deadline = time.monotonic() + timeout
        data = b""
        while len(data) < size:
            chunk = self.port.read(size - len(data))
            if chunk:
                data += chunk
            elif time.monotonic() > deadline:
                break
        return data

    def _descriptor(self, cmd: int, timeout: float, check: Any = None) -> rp.Descriptor:
        """Skip to ``0xA5 0x5A`` and read the descriptor; check it is ``cmd``'s (or with ``check``)."""
        deadline = time.monotonic() + timeout
        prev = b""
        while True:
            b = self.port.read(1)
            if not b:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"no answer to {rp.COMMAND_NAMES[cmd]} within {timeout:.1f} s")
                continue
            if prev == b"\xa5" and b == b"\x5a":
                rest = self._read_exact(5, timeout)
                if len(rest) < 5:
                    raise TimeoutError(f"the answer to {rp.COMMAND_NAMES[cmd]} stopped in its descriptor")
                d = rp.Descriptor.unpack(b"\xa5\x5a" + rest)
                if check is None:
                    d.check(cmd)
                else:
                    check(d, cmd)
                return d
            prev = b

    def ask(
        self,
        cmd: int,
        payload_request: bytes | None = None,
        timeout: float = ANSWER_TIMEOUT,
        check: Any = None,
    ) -> bytes:
        """Send ``cmd`` and return its single answer's data."""
        self.port.reset_input_buffer()
        self.port.write(payload_request if payload_request is not None else rp.request(cmd))
        d = self._descriptor(cmd, timeout, check)
        data = self._read_exact(d.length, timeout)
        if len(data) < d.length:
            raise TimeoutError(
                f"the answer to {rp.COMMAND_NAMES[cmd]} stopped after {len(data)} of {d.length} bytes"
            )
        return data

    def device_info(self) -> rp.DeviceInfo:
        return rp.DeviceInfo.unpack(self.ask(rp.CMD_GET_INFO))

    def health(self) -> rp.Health:
        return rp.Health.unpack(self.ask(rp.CMD_GET_HEALTH))

    def sample_rates(self) -> tuple[int, int]:
        std, express = rp.struct.unpack("<HH", self.ask(rp.CMD_GET_SAMPLERATE))
        return std, express

    def lidar_conf(self, conf_type: int, mode_id: int | None = None) -> bytes:
        """GET_LIDAR_CONF: the value of one entry (RplidarError if the answer is not that entry's)."""
        data = self.ask(
            rp.CMD_GET_LIDAR_CONF,
            rp.lidar_conf_request(conf_type, mode_id),
            check=lambda d, cmd: d.check_single(cmd, rp.ANS_TYPE_GET_LIDAR_CONF),
        )
        return rp.parse_lidar_conf(conf_type, data)

    def check_motor_ctrl(self) -> bool:
        """GET_ACC_BOARD_FLAG: A2/A3 (and A1 on an accessory board) take SET_MOTOR_PWM; others use DTR."""
        try:
            data = self.ask(rp.CMD_GET_ACC_BOARD_FLAG, rp.acc_board_flag_request(), timeout=0.3)
        except (TimeoutError, rp.RplidarError):
            data = b"\x00\x00\x00\x00"
        self.motor_ctrl = bool(rp.struct.unpack("<I", data)[0] & 1)
        return self.motor_ctrl

    def _set_dtr(self, value: bool) -> None:
        try:
            self.port.dtr = value
        except (OSError, ValueError, AttributeError):
            pass  # a pseudo-terminal or a USB bridge without modem lines: nothing to switch

    def start_motor(self) -> None:
        if self.motor_ctrl:
            self.port.write(rp.motor_pwm_request(rp.DEFAULT_MOTOR_PWM))
        else:
            self._set_dtr(False)  # A1: DTR low powers the motor

    def stop_motor(self) -> None:
        if self.motor_ctrl:
            self.port.write(rp.motor_pwm_request(0))
        else:
            self._set_dtr(True)

    def reset(self) -> None:
        self.port.write(rp.request(rp.CMD_RESET))
        time.sleep(0.002)

    def stop(self) -> None:
        self.port.write(rp.request(rp.CMD_STOP))
        time.sleep(0.002)  # the protocol asks for 1 ms before the next request
        self.port.reset_input_buffer()

    def start_scan(self, mode: ScanMode) -> None:
        self.stop()
        self.port.reset_input_buffer()
        if mode.cmd == rp.CMD_EXPRESS_SCAN:
            self.port.write(rp.express_scan_request(mode.working_mode))
        else:
            self.port.write(rp.request(rp.CMD_SCAN))
        self._descriptor(mode.cmd, ANSWER_TIMEOUT, lambda d, cmd: d.check_stream(cmd, mode.ans_type))


def supported_modes(dev: RplidarDevice, info: rp.DeviceInfo) -> list[ScanMode]:
    """The device's scan modes: listed by the device from firmware 1.24 (GET_LIDAR_CONF), else the
    legacy protocol's Standard, and Express on firmware 1.17 and later."""
    if info.firmware_version >= rp.CONF_FIRMWARE:
        return conf_modes(dev)
    try:
        std_us, express_us = dev.sample_rates()
    except (TimeoutError, rp.RplidarError):
        std_us, express_us = 500, 0  # early A1 firmware: 2 kHz standard scans only
    modes = [ScanMode(0, "Standard", float(std_us), LEGACY_MAX_DISTANCE, rp.ANS_TYPE_MEASUREMENT)]
    if info.firmware_version >= (1 << 8 | 17) and express_us:
        modes.append(
            ScanMode(1, "Express", float(express_us), LEGACY_MAX_DISTANCE, rp.ANS_TYPE_MEASUREMENT_CAPSULED)
        )
    return modes


def conf_modes(dev: RplidarDevice) -> list[ScanMode]:
    """GET_LIDAR_CONF: the mode count, then each mode's microseconds per sample and range (1/256 units,
    whole numbers kept as the SDK keeps them), answer type and name (NUL-terminated)."""
    (count,) = rp.struct.unpack_from("<H", _sized(dev.lidar_conf(rp.CONF_SCAN_MODE_COUNT), 2, "mode count"))
    modes = []
    for ident in range(count):
        us = _sized(dev.lidar_conf(rp.CONF_SCAN_MODE_US_PER_SAMPLE, ident), 4, "us per sample")
        dist = _sized(dev.lidar_conf(rp.CONF_SCAN_MODE_MAX_DISTANCE, ident), 4, "max distance")
        ans_type = dev.lidar_conf(rp.CONF_SCAN_MODE_ANS_TYPE, ident)[0]
        name = dev.lidar_conf(rp.CONF_SCAN_MODE_NAME, ident).split(b"\0", 1)[0].decode("ascii", "replace")
        us_per_sample = float(rp.struct.unpack_from("<I", us)[0] >> 8)
        if us_per_sample <= 0:
            raise rp.RplidarError(f"scan mode {ident} ({name}) has {us_per_sample} us per sample")
        max_distance = float(rp.struct.unpack_from("<I", dist)[0] >> 8)
        modes.append(ScanMode(ident, name, us_per_sample, max_distance, ans_type))
    return modes


def typical_mode_id(dev: RplidarDevice, info: rp.DeviceInfo) -> int:
    """The mode rplidar_ros starts when ``scan_mode`` is empty: the device's typical one (or Express)."""
    if info.firmware_version >= rp.CONF_FIRMWARE:
        (ident,) = rp.struct.unpack_from(
            "<H", _sized(dev.lidar_conf(rp.CONF_SCAN_MODE_TYPICAL), 2, "typical")
        )
        return int(ident)
    return rp.SCAN_MODE_EXPRESS


def _sized(value: bytes, size: int, what: str) -> bytes:
    if len(value) < size:
        raise rp.RplidarError(f"GET_LIDAR_CONF {what}: {len(value)} bytes, expected {size}")
    return value


class RplidarNode:
    def __init__(self, node: Any, port: Any, dev: RplidarDevice) -> None:
        self.node = node
        self.log = node.log
        self.port = port
        self.dev = dev
        self.LaserScan: Any = get_message_class("sensor_msgs/LaserScan")
        self.frame_id = str(node.get_param("~frame_id", "laser_frame"))
        self.inverted = bool(node.get_param("~inverted", False))
        self.angle_compensate = bool(node.get_param("~angle_compensate", False))
        self.scan_mode_name = str(node.get_param("~scan_mode", ""))
        self.initial_reset = bool(node.get_param("~initial_reset", False))  # rplidar_ros 2.x
        # rplidar_ros 2.x: the turn rate the compensation bins are sized for (an A-series motor still
        # runs at its PWM default; 2.x sets the rate itself only on S/T-series lidars)
        self.scan_frequency: Any = node.get_param("~scan_frequency", 10.0)
        self.pub = node.publisher("scan", self.LaserScan, queue_size=1000)
        self.actions: queue.Queue[tuple[str, threading.Event]] = queue.Queue()
        self.scanning = False
        self.stopped = False  # by stop_motor: no scan until start_motor
        self.mode: ScanMode | None = None
        self.published = 0
        self.bad_logged, self.bad_log_time = 0, 0.0

    def _service(self, action: str) -> Any:
        Empty: Any = get_service_class("std_srvs/Empty")

        def handle(_req: Any) -> Any:
            done = threading.Event()
            self.actions.put((action, done))
            done.wait(5.0)
            return Empty._response_class()

        return self.node.service(action, Empty, handle)

    def _reset_device(self) -> bool:
        """rplidar_ros 2.x's ``initial_reset``: RESET, then GET_INFO every 0.5 s until the device
        answers again (its boot banner is skipped by the descriptor search), 15 s at most."""
        self.log.info("Resetting rplidar")
        self.dev.reset()
        deadline = time.monotonic() + RESET_TIMEOUT
        while not self.node.is_shutdown:
            self.node.wait_for_shutdown(0.5)
            try:
                self.dev.device_info()
            except (TimeoutError, rp.RplidarError):
                if time.monotonic() > deadline:
                    break
                continue
            self.log.info("Rplidar reset successfully")
            return True
        self.log.error("Error resetting rplidar")
        return False

    def setup(self) -> int:
        self.log.info("RPLIDAR running on ROS package rplidar_ros. SDK Version:%s", SDK_VERSION)
        freq = self.scan_frequency
        if isinstance(freq, bool) or not isinstance(freq, int | float) or not 0 < freq < 100:
            self.log.error(
                "Error, scan_frequency must be a number of Hz above 0 (and below 100), got %r", freq
            )
            return 1
        self.scan_frequency = float(freq)
        try:
            info = self.dev.device_info()
        except TimeoutError:
            self.log.error("Error, operation time out. RESULT_OPERATION_TIMEOUT! ")
            return 1
        except rp.RplidarError as exc:
            self.log.error("Error, unexpected answer to GET_INFO: %s", exc)
            return 1
        self.log.info("RPLIDAR S/N: %s", info.serialnum.hex().upper())
        self.log.info("Firmware Ver: %d.%02d", info.firmware_version >> 8, info.firmware_version & 0xFF)
        self.log.info("Hardware Rev: %d", info.hardware_version)
        if self.initial_reset and not self._reset_device():
            return 1
        try:
            health = self.dev.health()
        except (TimeoutError, rp.RplidarError) as exc:
            self.log.error("Error, cannot retrieve rplidar health code: %s", exc)
            return 1
        self.log.info("RPLidar health status : %d", health.status)
        if health.status == rp.STATUS_ERROR:
            self.log.error("Error, rplidar internal error detected. Please reboot the device to retry.")
            # the protocol's way out of the protection stop: a core reset, so the next start may work
            self.dev.reset()
            return 1
        if health.status == rp.STATUS_WARNING:
            self.log.warn("RPLidar health warning, error code: %d", health.error_code)
        self._service("stop_motor")
        self._service("start_motor")
        self.dev.check_motor_ctrl()
        self.dev.start_motor()
        try:
            modes = supported_modes(self.dev, info)
            typical = typical_mode_id(self.dev, info) if not self.scan_mode_name else None
        except (TimeoutError, rp.RplidarError) as exc:
            self.log.error("Error, cannot get the scan modes of the lidar: %s", exc)
            return 1
        by_id = {m.id: m for m in modes}
        if self.scan_mode_name:
            chosen = [m for m in modes if m.name == self.scan_mode_name]
            if not chosen:
                self.log.error(
                    "scan mode `%s' is not supported by lidar, supported modes:", self.scan_mode_name
                )
                for m in modes:
                    self.log.error(
                        "\t%s: max_distance: %.1f m, Point number: %.1fK",
                        m.name,
                        m.max_distance,
                        1000.0 / m.us_per_sample,
                    )
                # rplidar_ros stays up without a scan (RESULT_OPERATION_FAIL); its start_motor service
                # then starts the typical mode, which is kept ready here
                self.log.error("Can not start scan: %08x!", RESULT_OPERATION_FAIL)
                try:
                    typical = typical_mode_id(self.dev, info)
                except (TimeoutError, rp.RplidarError) as exc:
                    self.log.error("Error, cannot get the scan modes of the lidar: %s", exc)
                    return 1
                self.stopped = True
            else:
                self.mode = chosen[0]
        if self.mode is None:
            # the typical mode (legacy: Express when the device has it, else Standard)
            self.mode = by_id.get(typical if typical is not None else -1, modes[-1])
        if self.mode.ans_type not in DECODERS:
            self.log.error(
                "scan mode `%s' streams answers of type 0x%02X, which this driver does not decode "
                "(it decodes 0x81, 0x82, 0x84 and 0x85)",
                self.mode.name,
                self.mode.ans_type,
            )
            return 1
        self.multiple = compensate_multiple(self.mode.us_per_sample, self.scan_frequency)
        return 0

    def _start_scan(self, quiet: bool) -> bool:
        assert self.mode is not None
        try:
            self.dev.start_scan(self.mode)
        except (TimeoutError, rp.RplidarError) as exc:
            if not quiet:
                self.log.error("Can not start scan: %s", exc)
            return False
        self.log.info(
            "current scan mode: %s, max_distance: %.1f m, Point number: %.1fK , angle_compensate: %d",
            self.mode.name,
            self.mode.max_distance,
            1000.0 / self.mode.us_per_sample,
            self.multiple,
        )
        self.scanning = True
        return True

    def _do(self, action: str) -> None:
        if action == "stop_motor":
            self.log.debug("Stop motor")
            self.dev.stop()
            self.dev.stop_motor()
            self.scanning = False
            self.stopped = True
        else:
            self.log.debug("Start motor")
            self.stopped = False
            self.dev.start_motor()
            self._start_scan(quiet=False)

    def _decoder(self) -> Any:
        assert self.mode is not None
        self.bad_logged, self.bad_log_time = 0, 0.0
        return DECODERS[self.mode.ans_type]()

    def _report_bad(self, decoder: Any) -> None:
        """One line (at most a second apart) for the bytes dropped since the last one."""
        bad = getattr(decoder, "bad", None)
        if bad is None:
            bad = decoder.discarded
        if bad > self.bad_logged and time.monotonic() - self.bad_log_time >= BAD_DATA_LOG_INTERVAL:
            assert self.mode is not None
            self.log.warn(
                "RPLIDAR: dropped %d byte(s) of %s scan data that failed the sync or checksum check",
                bad - self.bad_logged,
                self.mode.name,
            )
            self.bad_logged, self.bad_log_time = bad, time.monotonic()

    def run(self) -> None:
        assert self.mode is not None
        decoder = self._decoder()
        assembler = RevolutionAssembler()
        failed_once = False
        next_try = 0.0
        rev_start = time.monotonic()
        rev_stamp = self.node.now()
        while not self.node.is_shutdown:
            try:
                action, done = self.actions.get_nowait()
            except queue.Empty:
                pass
            else:
                self._do(action)
                decoder = self._decoder()
                assembler.reset()
                rev_start, rev_stamp = time.monotonic(), self.node.now()
                done.set()
                continue
            if not self.scanning:
                if self.stopped or time.monotonic() < next_try:
                    self.node.wait_for_shutdown(0.05)
                    continue
                if not self._start_scan(quiet=failed_once):
                    failed_once = True
                    next_try = time.monotonic() + 1.0
                    continue
                decoder = self._decoder()
                assembler.reset()
                rev_start, rev_stamp = time.monotonic(), self.node.now()
            waiting = self.port.in_waiting
            if 0 < waiting < BATCH_BYTES:
                # let a few measurements gather: one wake-up per 10 ms, not one per capsule
                self.node.wait_for_shutdown(BATCH_WAIT)
                waiting = self.port.in_waiting
            data = self.port.read(waiting if waiting else 1)  # blocks up to READ_TIMEOUT when idle
            if not data:
                continue
            rows = decoder.feed(data)
            self._report_bad(decoder)
            for rev in assembler.feed(rows):
                now = time.monotonic()
                self._publish(rev, rev_stamp, now - rev_start)
                rev_start, rev_stamp = now, self.node.now()

    def _publish(self, rev: Any, stamp: Any, duration: float) -> None:
        assert self.mode is not None
        f = revolution_to_scan(
            rev, self.angle_compensate, self.multiple, duration, self.inverted, self.mode.max_distance
        )
        msg = self.LaserScan()
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame_id
        msg.angle_min, msg.angle_max, msg.angle_increment = f.angle_min, f.angle_max, f.angle_increment
        msg.time_increment, msg.scan_time = f.time_increment, f.scan_time
        msg.range_min, msg.range_max = f.range_min, f.range_max
        msg.ranges = f.ranges
        msg.intensities = f.intensities
        self.pub.publish(msg)
        self.published += 1


def open_port(path: str, baud: int) -> Any:
    import serial  # type: ignore[import-untyped]  # pyserial, imported when a node starts (no work at import)

    return serial.Serial(path, baud, timeout=READ_TIMEOUT, write_timeout=2.0)


def main(argv: list[str] | None = None) -> int:
    """``rosrun rplidar_ros rplidarNode``."""

    def build(node: Any) -> int:
        channel = str(node.get_param("~channel_type", "serial"))
        if channel != "serial":  # rplidar_ros 2.x: S-series lidars on Ethernet
            node.log.error(
                "Error, channel_type %s is not supported here: this rplidarNode speaks to the lidar on a "
                "serial port only (channel_type serial, serial_port, serial_baudrate)",
                channel,
            )
            return 1
        path = str(node.get_param("~serial_port", "/dev/ttyUSB0"))
        baud = int(node.get_param("~serial_baudrate", 115200))
        try:
            port = open_port(path, baud)
        except (OSError, ValueError):
            node.log.info("RPLIDAR running on ROS package rplidar_ros. SDK Version:%s", SDK_VERSION)
            node.log.error("Error, cannot bind to the specified serial port %s.", path)
            return 1
        dev = RplidarDevice(port)
        lidar = RplidarNode(node, port, dev)
        try:
            code = lidar.setup()
            if code:
                return code
            lidar.run()
        except OSError as exc:
            if not node.is_shutdown:
                node.log.error("RPLIDAR: the serial port failed: %s", exc)
                return 1
        finally:
            try:
                dev.stop()
                dev.stop_motor()
            except OSError:
                pass
            port.close()
        return 0

    # ros::init's name in rplidar_ros (the launch files name the node rplidarNode)
    return run_node("rplidar_node", argv, build)
