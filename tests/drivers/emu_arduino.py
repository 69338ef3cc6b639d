"""An emulated Arduino motor board speaking rosserial, written from the protocol description.

It behaves as a ``rosserial_arduino`` sketch (ros_lib's NodeHandle) would: it waits for the host's topic
request, answers with one ``rosserial_msgs/TopicInfo`` per endpoint, asks for the time (and again every
``sync_period`` seconds), requests the ``wheel_radius`` parameter and logs a line once configured. It
publishes the wheel speeds ``wl`` and ``wr`` (std_msgs/Float32, rad/s) computed from the last
``cmd_vel`` (geometry_msgs/Twist) by differential-drive kinematics, subscribes the LED ring topic
``led`` (std_msgs/ColorRGBA), provides the service ``reset_encoders`` (std_srvs/Trigger) and calls the
ROS service ``board_config`` (std_srvs/Trigger) when ``call_config()`` is used.

The board sits on the master side of a pseudo-terminal (``os.openpty``): the host opens ``path`` as it
would open /dev/ttyACM0. ``connect_tcp(port)`` puts it on a TCP connection instead (rosserial over
WiFi). ``inject(bytes)`` writes raw bytes toward the host (noise, broken packets).
"""

from __future__ import annotations

import os
import select
import socket
import threading
import time
import tty
from typing import Any

from ninjemys.drivers import rosserial_protocol as proto
from ninjemys.idl.loader import get_message_class, get_service_class

TopicInfo = get_message_class("rosserial_msgs/TopicInfo")
Log = get_message_class("rosserial_msgs/Log")
Time = get_message_class("std_msgs/Time")
Float32 = get_message_class("std_msgs/Float32")
Twist = get_message_class("geometry_msgs/Twist")
ColorRGBA = get_message_class("std_msgs/ColorRGBA")
RequestParam = get_service_class("rosserial_msgs/RequestParam")
Trigger = get_service_class("std_srvs/Trigger")

# ros_lib numbers subscribers from 100 and publishers from 100 + MAX_SUBSCRIBERS (25 on an Uno)
SUB_CMD_VEL, SUB_LED, SUB_RESET, SUB_CONFIG = 100, 101, 102, 103
PUB_WL, PUB_WR, PUB_RESET, PUB_CONFIG = 125, 126, 127, 128
WHEEL_BASE = 0.19  # m, the PuzzleBot's track
BUFFER = 280  # bytes, an Uno's default buffers


def _info(topic_id: int, name: str, type_name: str, md5: str) -> bytes:
    ti = TopicInfo()
    ti.topic_id, ti.topic_name, ti.message_type, ti.md5sum, ti.buffer_size = (
        topic_id,
        name,
        type_name,
        md5,
        BUFFER,
    )
    return ti.serialize_to_bytes()


class EmulatedArduino:
    def __init__(self, rate_hz: float = 20.0, sync_period: float = 5.0) -> None:
        self.rate_hz = rate_hz
        self.sync_period = sync_period
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self._sock: socket.socket | None = None
        self.reader = proto.FrameReader()
        self.lock = threading.Lock()
        self.cond = threading.Condition()
        self.configured = False
        self.negotiations = 0
        self.time_syncs = 0
        self.host_time: tuple[int, int] | None = None
        self.wheel_radius: float | None = None
        self.param_answers: list[Any] = []  # every RequestParam response, in order
        self.received: list[tuple[int, int]] = []  # (topic id, payload length) of every packet from the host
        self.param_answers_only = False  # True: a test's own requests, wheel_radius left alone
        self.cmd_vels: list[Any] = []
        self.leds: list[Any] = []
        self.resets = 0
        self.config_answers: list[Any] = []
        self.stopped_by_host = False
        self.drops = 0
        self.sync_enabled = True  # False: stop asking for the time (a hung sketch), the host must notice
        self.published = 0
        self._stop = threading.Event()
        self._last_sync = 0.0
        self.wl = 0.0
        self.wr = 0.0
        self.threads = [
            threading.Thread(target=self._read_loop, name="arduino-rx", daemon=True),
            threading.Thread(target=self._publish_loop, name="arduino-tx", daemon=True),
        ]
        for t in self.threads:
            t.start()

    # -- links ---------------------------------------------------------------------------------------

    def connect_tcp(self, port: int, timeout: float = 20.0) -> None:
        """Leave the pty and dial the host's TCP port (retrying while it starts)."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                sock = socket.create_connection(("127.0.0.1", port), timeout=1.0)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        sock.settimeout(None)
        with self.lock:
            self._sock = sock

    def _write(self, data: bytes) -> None:
        with self.lock:
            if self._sock is not None:
                self._sock.sendall(data)
            else:
                os.write(self.master, data)

    def _read(self) -> bytes:
        sock = self._sock
        if sock is not None:
            ready, _, _ = select.select([sock], [], [], 0.1)
            return sock.recv(4096) if ready else b""
        ready, _, _ = select.select([self.master], [], [], 0.1)
        if not ready:
            return b""
        try:
            return os.read(self.master, 4096)
        except OSError:  # EIO: no process holds the pty's other side right now
            time.sleep(0.05)
            return b""

    def inject(self, data: bytes) -> None:
        self._write(data)

    def send(self, topic_id: int, payload: bytes) -> None:
        self._write(proto.frame(topic_id, payload))

    # -- device behaviour -------------------------------------------------------------------------------

    def _negotiate(self) -> None:
        f32, tw, rgba, trig = Float32._md5sum, Twist._md5sum, ColorRGBA._md5sum, Trigger._md5sum
        self.send(proto.ID_TIME, Time().serialize_to_bytes())
        self._last_sync = time.monotonic()
        for tid, name, typ, md5 in (
            (PUB_WL, "wl", "std_msgs/Float32", f32),
            (PUB_WR, "wr", "std_msgs/Float32", f32),
        ):
            self.send(proto.ID_PUBLISHER, _info(tid, name, typ, md5))
        self.send(proto.ID_SUBSCRIBER, _info(SUB_CMD_VEL, "cmd_vel", "geometry_msgs/Twist", tw))
        self.send(proto.ID_SUBSCRIBER, _info(SUB_LED, "led", "std_msgs/ColorRGBA", rgba))
        self.send(
            proto.ID_SERVICE_SERVER + proto.ID_PUBLISHER,
            _info(PUB_RESET, "reset_encoders", "std_srvs/Trigger", trig),
        )
        self.send(
            proto.ID_SERVICE_SERVER + proto.ID_SUBSCRIBER,
            _info(SUB_RESET, "reset_encoders", "std_srvs/Trigger", trig),
        )
        self.send(
            proto.ID_SERVICE_CLIENT + proto.ID_PUBLISHER,
            _info(PUB_CONFIG, "board_config", "std_srvs/Trigger", trig),
        )
        self.send(
            proto.ID_SERVICE_CLIENT + proto.ID_SUBSCRIBER,
            _info(SUB_CONFIG, "board_config", "std_srvs/Trigger", trig),
        )
        req = RequestParam._request_class()
        req.name = "wheel_radius"
        self.send(proto.ID_PARAMETER_REQUEST, req.serialize_to_bytes())
        log = Log()
        log.level, log.msg = Log.WARN, "PuzzleBot board: motors armed"
        self.send(proto.ID_LOG, log.serialize_to_bytes())
        with self.cond:
            self.negotiations += 1
            self.configured = True
            self.cond.notify_all()

    def _handle(self, f: proto.Frame) -> None:
        tid = f.topic_id
        with self.cond:
            self.received.append((tid, len(f.payload)))
            if tid == proto.ID_PUBLISHER:
                pass
            elif tid == proto.ID_TIME:
                t = Time().deserialize(f.payload)
                self.host_time = (t.data.secs, t.data.nsecs)
                self.time_syncs += 1
            elif tid == proto.ID_PARAMETER_REQUEST:
                resp = RequestParam._response_class().deserialize(f.payload)
                with self.cond:
                    self.param_answers.append(resp)  # ros_lib takes them in order, one at a time
                    self.cond.notify_all()
                if self.param_answers_only:
                    pass
                elif resp.floats or resp.ints:
                    self.wheel_radius = resp.floats[0] if resp.floats else float(resp.ints[0])
            elif tid == proto.ID_TX_STOP:
                self.stopped_by_host = True
                self.configured = False
            elif tid == SUB_CMD_VEL:
                tw = Twist().deserialize(f.payload)
                self.cmd_vels.append(tw)
                r = self.wheel_radius or 0.05
                v, w = tw.linear.x, tw.angular.z
                self.wl, self.wr = (v - w * WHEEL_BASE / 2) / r, (v + w * WHEEL_BASE / 2) / r
            elif tid == SUB_LED:
                self.leds.append(ColorRGBA().deserialize(f.payload))
            elif tid == SUB_RESET:
                self.resets += 1
            elif tid == SUB_CONFIG:
                self.config_answers.append(Trigger._response_class().deserialize(f.payload))
            self.cond.notify_all()
        if tid == proto.ID_PUBLISHER:
            self._negotiate()
        elif tid == SUB_RESET:
            resp = Trigger._response_class()
            resp.success, resp.message = True, f"encoders reset ({self.resets})"
            self.send(PUB_RESET, resp.serialize_to_bytes())

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            try:
                data = self._read()
            except OSError:
                return
            for item in self.reader.feed(data):
                if isinstance(item, proto.Drop):
                    self.drops += 1
                else:
                    try:
                        self._handle(item)
                    except OSError:  # the host went away while the board answered it
                        return

    def _publish_loop(self) -> None:
        period = 1.0 / self.rate_hz
        while not self._stop.wait(period):
            if not self.configured:
                continue
            try:
                for tid, value in ((PUB_WL, self.wl), (PUB_WR, self.wr)):
                    m = Float32()
                    m.data = value
                    self.send(tid, m.serialize_to_bytes())
                self.published += 1
                if self.sync_enabled and time.monotonic() - self._last_sync > self.sync_period:
                    self._last_sync = time.monotonic()
                    self.send(proto.ID_TIME, Time().serialize_to_bytes())
            except OSError:
                continue

    def call_config(self) -> None:
        """The sketch calls the ROS service ``board_config``; the answer lands in ``config_answers``."""
        self.send(PUB_CONFIG, Trigger._request_class().serialize_to_bytes())

    def wait(self, pred: Any, timeout: float = 20.0) -> None:
        with self.cond:
            if not self.cond.wait_for(pred, timeout):
                raise AssertionError("the emulated Arduino did not see what was expected")

    def close(self) -> None:
        self._stop.set()
        for t in self.threads:
            t.join(2)
        if self._sock is not None:
            self._sock.close()
        os.close(self.master)
        os.close(self.slave)
