"""The Linux joystick API (``/dev/input/js*``) as joy_node reads it: events in, ``sensor_msgs/Joy``
state out, no node.

A ``struct js_event`` is 8 bytes: ``u32 time`` (ms), ``s16 value``, ``u8 type``, ``u8 number``.
The kernel sends one ``JS_EVENT_INIT``-flagged event per button and axis when the device is opened
(its state then), then one event per change. :class:`JoyState` applies them as ROS 1's joy_node
does: axis values are scaled to [-1, 1] with the sign flipped (``-raw/32767``: the kernel reports
a stick pushed up or left as negative, so up and left are positive, as REP 103's x-forward,
y-left wants), a dead zone cut out of the travel with the rest rescaled smoothly, buttons as 0/1 (or toggles with
``sticky_buttons``), and arrays that grow to the highest number seen. Whether an event publishes at
once (a button), after the coalesce interval (an axis, or any init event) or not at all is returned
to the caller, which owns the clock.
"""

from __future__ import annotations

import fcntl
import glob
import os
import struct
from dataclasses import dataclass, field
from enum import Enum

from ninjemys.errors import NinjemysError

EVENT = struct.Struct("<IhBB")
JS_EVENT_BUTTON = 0x01
JS_EVENT_AXIS = 0x02
JS_EVENT_INIT = 0x80
AXIS_MAX = 32767.0

# JSIOCGNAME(len) = _IOC(_IOC_READ, 'j', 0x13, len)
_IOC_READ = 2


def jsiocgname(length: int) -> int:
    """The ioctl request that reads a joystick's name into ``length`` bytes."""
    return (_IOC_READ << 30) | (length << 16) | (ord("j") << 8) | 0x13


class JoystickError(NinjemysError):
    """A joystick parameter or event the driver cannot use (says which and why)."""


class Publish(Enum):
    """What an event asks of the publishing loop."""

    NONE = 0
    NOW = 1  # a button changed: publish at once
    SOON = 2  # an axis moved (or an init event): publish after the coalesce interval


@dataclass
class JoyEvent:
    time_ms: int
    value: int
    type: int
    number: int

    @classmethod
    def unpack(cls, data: bytes, offset: int = 0) -> JoyEvent:
        return cls(*EVENT.unpack_from(data, offset))

    def pack(self) -> bytes:
        return EVENT.pack(self.time_ms & 0xFFFFFFFF, self.value, self.type, self.number)


@dataclass
class JoySettings:
    """joy_node's parameters after its checks (see :func:`checked_settings`)."""

    deadzone: float = 0.05
    autorepeat_rate: float = 0.0
    coalesce_interval: float = 0.001
    default_trig_val: bool = False
    sticky_buttons: bool = False

    @property
    def autorepeat_interval(self) -> float | None:
        return 1.0 / self.autorepeat_rate if self.autorepeat_rate > 0 else None


def checked_settings(
    deadzone: float,
    autorepeat_rate: float,
    coalesce_interval: float,
    default_trig_val: bool = False,
    sticky_buttons: bool = False,
) -> tuple[JoySettings, list[str]]:
    """The settings joy_node ends up with, and its warnings, in its order: an old-style dead zone
    (>= 1, in raw units) is divided by 32767, then clamped to [0, 0.9]; negative rates become 0."""
    warnings: list[str] = []
    if coalesce_interval > 0 and autorepeat_rate > 1.0 / coalesce_interval:
        warnings.append(
            f"joy_node: autorepeat_rate ({autorepeat_rate:f} Hz) > 1/coalesce_interval "
            f"({1.0 / coalesce_interval:f} Hz) does not make sense. Timing behavior is not well defined."
        )
    if deadzone >= 1:
        warnings.append(
            "joy_node: deadzone greater than 1 was requested. The semantics of deadzone have changed. "
            "It is now related to the range [-1:1] instead of [-32767:32767]. For now I am dividing your "
            "deadzone by 32767, but this behavior is deprecated so you need to update your launch file."
        )
        deadzone /= AXIS_MAX
    if deadzone > 0.9:
        warnings.append(f"joy_node: deadzone ({deadzone:f}) greater than 0.9, setting it to 0.9")
        deadzone = 0.9
    if deadzone < 0:
        warnings.append(f"joy_node: deadzone_ ({deadzone:f}) less than 0, setting to 0.")
        deadzone = 0.0
    if autorepeat_rate < 0:
        warnings.append(f"joy_node: autorepeat_rate ({autorepeat_rate:f}) less than 0, setting to 0.")
        autorepeat_rate = 0.0
    if coalesce_interval < 0:
        warnings.append(f"joy_node: coalesce_interval ({coalesce_interval:f}) less than 0, setting to 0.")
        coalesce_interval = 0.0
    return (
        JoySettings(deadzone, autorepeat_rate, coalesce_interval, default_trig_val, sticky_buttons),
        warnings,
    )


@dataclass
class JoyState:
    """The axes and buttons of one opened device (a new one per open, as joy_node resets them)."""

    settings: JoySettings
    axes: list[float] = field(default_factory=list)
    buttons: list[int] = field(default_factory=list)

    def scaled(self, raw: int) -> float:
        """A raw axis value in [-1, 1], sign flipped, with the dead zone cut out of the travel."""
        dz = self.settings.deadzone
        unscaled_deadzone = AXIS_MAX * dz
        val = float(raw)
        if val > unscaled_deadzone:
            val -= unscaled_deadzone
        elif val < -unscaled_deadzone:
            val += unscaled_deadzone
        else:
            val = 0.0
        return val * (-1.0 / (1.0 - dz) / AXIS_MAX)

    def apply(self, event: JoyEvent) -> Publish:
        """Apply one event; what the loop should do about publishing. Unknown types raise."""
        kind = event.type & ~JS_EVENT_INIT
        init = bool(event.type & JS_EVENT_INIT)
        if kind == JS_EVENT_BUTTON:
            _grow(self.buttons, event.number, 0)
            if self.settings.sticky_buttons:
                if event.value == 1:
                    self.buttons[event.number] = 1 - self.buttons[event.number]
            else:
                self.buttons[event.number] = 1 if event.value else 0
            return Publish.SOON if init else Publish.NOW
        if kind == JS_EVENT_AXIS:
            _grow(self.axes, event.number, 0.0)
            # an init event leaves the axis at 0 unless default_trig_val asks for its real value
            # (triggers rest at -1 raw, which joy_node would otherwise report only once moved)
            if self.settings.default_trig_val or not init:
                self.axes[event.number] = self.scaled(event.value)
            return Publish.SOON
        raise JoystickError(
            "joy_node: Unknown event type. Please file a ticket. "
            f"time={event.time_ms}, value={event.value}, type={event.type:X}h, number={event.number}"
        )


def _grow(values: list, index: int, fill: float | int) -> None:
    if index >= len(values):
        values.extend([fill] * (index + 1 - len(values)))


def device_name(fd: int) -> str:
    """The joystick's name from the driver, or "Unknown" (a FIFO or a device without the ioctl)."""
    buf = bytearray(128)
    try:
        fcntl.ioctl(fd, jsiocgname(len(buf)), buf)
    except OSError:
        return "Unknown"
    return bytes(buf).split(b"\0", 1)[0].decode("utf-8", "replace") or "Unknown"


def device_by_name(name: str, pattern: str = "/dev/input/js*") -> str | None:
    """The first joystick device whose driver name is ``name`` (joy_node's ``~dev_name``)."""
    for path in sorted(glob.glob(pattern)):
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        except OSError:
            continue
        try:
            if device_name(fd) == name:
                return path
        finally:
            os.close(fd)
    return None
