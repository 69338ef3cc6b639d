"""``rosrun joy joy_node``: a Linux joystick on ``sensor_msgs/Joy``, as ROS 1's joy_node.

Parameters (private): ``~dev`` (/dev/input/js0), ``~dev_name`` (pick the device by its driver name
instead), ``~deadzone`` (0.05), ``~autorepeat_rate`` (0: publish only on change), ``~coalesce_interval``
(0.001 s: axis changes closer than this go out in one message), ``~default_trig_val``,
``~sticky_buttons``. Publishes ``joy`` (queue 1), stamped at publication with ``frame_id`` the device
path. A device that cannot be opened is retried every second (one error line); a device that goes
away (unplugged, or a FIFO whose writer closed) is reopened the same way, with fresh state.

``joy/set_feedback`` is subscribed as ROS 1 does; rumble needs the force-feedback event device
(``~dev_ff``), which this driver does not drive, so feedback is ignored as ROS 1 ignores it when
``dev_ff`` cannot be opened.
"""

from __future__ import annotations

import errno
import os
import select
import time
from typing import Any

from ninjemys.drivers.joystick import (
    EVENT,
    JoyEvent,
    JoySettings,
    JoyState,
    JoystickError,
    Publish,
    checked_settings,
    device_by_name,
    device_name,
)
from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node


def _msg(type_name: str) -> Any:
    """A message class, typed loosely: its fields are generated at run time."""
    return get_message_class(type_name)


#: how long a wait may last before the loop looks at shutdown (joy_node spins between selects)
_POLL = 0.1


class JoyNode:
    """The device loop: open, read events, publish on change, coalesce and autorepeat timers."""

    def __init__(self, node: Any) -> None:
        self.node = node
        self.log = node.log
        self.Joy = _msg("sensor_msgs/Joy")
        self.pub = node.publisher("joy", self.Joy, queue_size=1)
        self.feedback = node.subscriber(
            "joy/set_feedback",
            _msg("sensor_msgs/JoyFeedbackArray"),
            lambda _m: None,
            queue_size=10,
        )
        self.dev = str(node.get_param("~dev", "/dev/input/js0"))
        dev_name = str(node.get_param("~dev_name", ""))
        settings, warnings = checked_settings(
            float(node.get_param("~deadzone", 0.05)),
            float(node.get_param("~autorepeat_rate", 0.0)),
            float(node.get_param("~coalesce_interval", 0.001)),
            bool(node.get_param("~default_trig_val", False)),
            bool(node.get_param("~sticky_buttons", False)),
        )
        if dev_name:
            path = device_by_name(dev_name)
            if path is None:
                self.log.error(
                    "Couldn't find a joystick with name %s. Falling back to default device.", dev_name
                )
            else:
                self.log.info("Using %s as joystick device.", path)
                self.dev = path
        for line in warnings:
            self.log.warn("%s", line)
        self.settings: JoySettings = settings
        self.published = 0

    def run(self) -> None:
        quiet = False  # the last opening found the device at its end at once: do not say it again
        while not self.node.is_shutdown:
            fd = self._open()
            if fd is None:
                return
            try:
                if not quiet:
                    self.log.info(
                        "Opened joystick: %s (%s). deadzone_: %f.",
                        self.dev,
                        device_name(fd),
                        self.settings.deadzone,
                    )
                served = self._serve(fd)
            finally:
                os.close(fd)
            if self.node.is_shutdown:
                break
            quiet = not served
            if served:
                self.log.error("Connection to joystick device lost unexpectedly. Will reopen.")
            else:  # opened but at its end at once (a FIFO without a writer): do not spin
                self.node.wait_for_shutdown(1.0)

    def _open(self) -> int | None:
        """Open the device, retrying every second (ROS 1's open-close-open gets the current state
        from the driver, not the state at the last close)."""
        first = True
        while not self.node.is_shutdown:
            try:
                os.close(os.open(self.dev, os.O_RDONLY | os.O_NONBLOCK))
                return os.open(self.dev, os.O_RDONLY | os.O_NONBLOCK)
            except OSError:
                if first:
                    self.log.error("Couldn't open joystick %s. Will retry every second.", self.dev)
                    first = False
                self.node.wait_for_shutdown(1.0)
        return None

    def _serve(self, fd: int) -> bool:
        """Events until the device goes away or the node shuts down; True if any came."""
        got_any = False
        state = JoyState(self.settings)
        pending = b""
        deadline: float | None = None  # when the coalesce or autorepeat timer fires
        coalescing = False
        repeat = self.settings.autorepeat_interval
        while not self.node.is_shutdown:
            now = time.monotonic()
            wait = _POLL if deadline is None else min(_POLL, max(0.0, deadline - now))
            ready, _, _ = select.select([fd], [], [], wait)
            if ready:
                try:
                    data = os.read(fd, EVENT.size * 64)
                except OSError as exc:
                    if exc.errno in (errno.EAGAIN, errno.EINTR):
                        continue
                    return got_any  # the joystick is gone
                if not data:
                    return got_any  # end of stream: a FIFO's writer closed
                got_any = True
                pending += data
                usable = len(pending) - len(pending) % EVENT.size
                for offset in range(0, usable, EVENT.size):
                    try:
                        action = state.apply(JoyEvent.unpack(pending, offset))
                    except JoystickError as exc:
                        self.log.warn("%s", exc)
                        continue
                    if action is Publish.NOW:
                        self._publish(state)
                        deadline, coalescing = None, False
                    elif action is Publish.SOON and not coalescing:
                        deadline, coalescing = time.monotonic() + self.settings.coalesce_interval, True
                pending = pending[usable:]
            elif deadline is not None and time.monotonic() >= deadline:
                self._publish(state)
                deadline, coalescing = None, False
            if deadline is None and repeat is not None:
                deadline = time.monotonic() + repeat
        return got_any

    def _publish(self, state: JoyState) -> None:
        msg = self.Joy()
        msg.header.stamp = self.node.now()
        msg.header.frame_id = self.dev
        msg.axes = list(state.axes)
        msg.buttons = list(state.buttons)
        self.pub.publish(msg)
        self.published += 1


def main(argv: list[str] | None = None) -> int:
    """``rosrun joy joy_node``."""

    def build(node: Any) -> int:
        JoyNode(node).run()
        return 0

    return run_node("joy_node", argv, build)
