"""joy_node and teleop_twist_joy: js_event streams give the right sensor_msgs/Joy, and /cmd_vel moves
only while the enable button is held; the shipped teleop.launch brings both up on a FIFO joystick."""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from ninjemys import testing
from ninjemys.drivers.joystick import (
    JS_EVENT_AXIS,
    JS_EVENT_BUTTON,
    JS_EVENT_INIT,
    JoyEvent,
    JoyState,
    JoystickError,
    Publish,
    checked_settings,
    jsiocgname,
)
from ninjemys.drivers.teleop_twist_joy import Teleop, read_config
from ninjemys.idl.loader import get_message_class

Twist = get_message_class("geometry_msgs/Twist")
Joy = get_message_class("sensor_msgs/Joy")

if TYPE_CHECKING:
    from .conftest import Rig


def state(**kw: object) -> JoyState:
    settings, _ = checked_settings(
        float(kw.get("deadzone", 0.05)),  # type: ignore[arg-type]
        0.0,
        0.001,
        bool(kw.get("default_trig_val", False)),
        bool(kw.get("sticky_buttons", False)),
    )
    return JoyState(settings)


# -- the event decoder ---------------------------------------------------------------------------


def test_event_layout_is_the_kernels_8_byte_js_event() -> None:
    ev = JoyEvent(123456, -32767, JS_EVENT_AXIS, 3)
    data = ev.pack()
    assert len(data) == 8
    assert data == (123456).to_bytes(4, "little") + (-32767).to_bytes(2, "little", signed=True) + b"\x02\x03"
    assert JoyEvent.unpack(data) == ev
    # JSIOCGNAME(128) as <linux/joystick.h> defines it
    assert jsiocgname(128) == 0x80806A13


def test_axes_flip_sign_and_cut_the_dead_zone_smoothly() -> None:
    s = state(deadzone=0.1)
    assert s.apply(JoyEvent(0, 32767, JS_EVENT_AXIS, 0)) is Publish.SOON
    assert s.axes == [pytest.approx(-1.0)]
    s.apply(JoyEvent(0, -32767, JS_EVENT_AXIS, 0))
    assert s.axes[0] == pytest.approx(1.0)
    s.apply(JoyEvent(0, 3000, JS_EVENT_AXIS, 0))  # inside 0.1 * 32767
    assert s.axes[0] == 0.0
    raw = 20000
    s.apply(JoyEvent(0, raw, JS_EVENT_AXIS, 0))
    assert s.axes[0] == pytest.approx(-(raw - 3276.7) / (1 - 0.1) / 32767)
    s.apply(JoyEvent(0, 100, JS_EVENT_AXIS, 4))  # arrays grow to the highest number, zero-filled
    assert s.axes[1:] == [0.0, 0.0, 0.0, 0.0]


def test_init_events_set_buttons_but_leave_axes_at_zero_unless_default_trig_val() -> None:
    s = state()
    assert s.apply(JoyEvent(0, 1, JS_EVENT_BUTTON | JS_EVENT_INIT, 2)) is Publish.SOON
    assert s.buttons == [0, 0, 1]
    assert s.apply(JoyEvent(0, -32767, JS_EVENT_AXIS | JS_EVENT_INIT, 5)) is Publish.SOON
    assert s.axes == [0.0] * 6
    t = state(default_trig_val=True)
    t.apply(JoyEvent(0, -32767, JS_EVENT_AXIS | JS_EVENT_INIT, 5))
    assert t.axes[5] == pytest.approx(1.0)


def test_buttons_publish_at_once_and_sticky_buttons_toggle() -> None:
    s = state()
    assert s.apply(JoyEvent(0, 1, JS_EVENT_BUTTON, 0)) is Publish.NOW
    assert s.buttons == [1]
    s.apply(JoyEvent(0, 0, JS_EVENT_BUTTON, 0))
    assert s.buttons == [0]
    sticky = state(sticky_buttons=True)
    for value in (1, 0, 1, 0):
        sticky.apply(JoyEvent(0, value, JS_EVENT_BUTTON, 0))
    assert sticky.buttons == [0]
    sticky.apply(JoyEvent(0, 1, JS_EVENT_BUTTON, 0))
    assert sticky.buttons == [1]


def test_unknown_event_types_are_refused_with_joy_nodes_words() -> None:
    with pytest.raises(JoystickError, match="Unknown event type.*type=4h, number=1"):
        state().apply(JoyEvent(7, 0, 0x04, 1))


def test_parameters_are_checked_as_joy_node_checks_them() -> None:
    settings, warnings = checked_settings(3276.7, -1.0, -0.5)
    assert settings.deadzone == pytest.approx(0.1)
    assert settings.autorepeat_rate == 0.0 and settings.coalesce_interval == 0.0
    assert any("dividing your deadzone by 32767" in w for w in warnings)
    assert any("autorepeat_rate (-1.000000) less than 0" in w for w in warnings)
    settings, warnings = checked_settings(0.95, 2000.0, 0.001)
    assert settings.deadzone == 0.9
    assert any("greater than 0.9, setting it to 0.9" in w for w in warnings)
    assert any("does not make sense" in w for w in warnings)


# -- teleop ----------------------------------------------------------------------------------------


def params(values: dict[str, object]):  # noqa: ANN201
    return lambda key, default=None: values.get(key.lstrip("~"), default)


def test_cmd_vel_only_while_the_enable_button_is_held_and_one_stop_after() -> None:
    t = Teleop(
        read_config(
            params(
                {
                    "enable_button": 1,
                    "enable_turbo_button": 2,
                    "scale_linear": 0.7,
                    "scale_linear_turbo": 1.5,
                    "scale_angular": 0.4,
                }
            )
        ),
        Twist,
    )
    axes = [0.5, -1.0]
    assert t.on_joy(axes, [0, 0, 0]).linear.x == 0.0  # not held: one zero twist...
    assert t.on_joy(axes, [0, 0, 0]) is None  # ...then nothing
    held = t.on_joy(axes, [0, 1, 0])
    assert (held.linear.x, held.angular.z) == (pytest.approx(-0.7), pytest.approx(0.2))
    turbo = t.on_joy(axes, [0, 1, 1])
    assert (turbo.linear.x, turbo.angular.z) == (
        pytest.approx(-1.5),
        pytest.approx(0.2),
    )  # angular turbo = normal
    stop = t.on_joy(axes, [0, 0, 0])
    assert (stop.linear.x, stop.angular.z) == (0.0, 0.0)
    assert t.on_joy([], []) is None  # short arrays: not pressed, no crash


def test_require_enable_button_false_drives_without_a_button_and_turbo_still_wins() -> None:
    """The ROS 2 port's ``require_enable_button``, read so its config files work; true (the default)
    keeps ROS 1's rule."""
    t = Teleop(read_config(params({"require_enable_button": False, "enable_turbo_button": 3})), Twist)
    assert t.on_joy([0.0, 0.5], [0, 0, 0, 0]).linear.x == pytest.approx(0.25)
    assert t.on_joy([0.0, 0.5], [0, 0, 0, 1]).linear.x == pytest.approx(0.5)
    strict = Teleop(read_config(params({})), Twist)
    assert strict.on_joy([0.0, 0.5], [0]).linear.x == 0.0  # the one stop...
    assert strict.on_joy([0.0, 0.5], [0]) is None  # ...then nothing: the button is required
    assert strict.on_joy([0.0, 0.5], [1]).linear.x == pytest.approx(0.25)  # enable_button 0, scale 0.5


def test_holonomic_maps_and_axes_beyond_the_message() -> None:
    t = Teleop(
        read_config(
            params(
                {
                    "enable_button": 0,
                    "axis_linear": {"x": 1, "y": 0},
                    "scale_linear": {"x": 0.4, "y": 0.4},
                    "axis_angular": {"yaw": 7},
                    "scale_angular": {"yaw": 0.5},
                }
            )
        ),
        Twist,
    )
    msg = t.on_joy([0.25, 1.0, 0.0], [1])
    assert (msg.linear.x, msg.linear.y, msg.angular.z) == (pytest.approx(0.4), pytest.approx(0.1), 0.0)


# -- the nodes on a FIFO joystick ------------------------------------------------------------------


@pytest.fixture
def fifo(tmp_path: Path):  # noqa: ANN201
    path = tmp_path / "js0"
    os.mkfifo(path)
    fd = os.open(path, os.O_RDWR | os.O_NONBLOCK)  # a writer that never blocks on a missing reader
    yield path, fd
    os.close(fd)


def send(fd: int, *events: JoyEvent) -> None:
    os.write(fd, b"".join(e.pack() for e in events))


def test_teleop_launch_drives_cmd_vel_from_a_fifo_joystick(fifo, rig: Rig) -> None:  # noqa: ANN001
    path, fd = fifo
    node = rig.node("joy_test")
    joys, twists = rig.collect(node, "/joy", Joy), rig.collect(node, "/cmd_vel", Twist)
    rig.roslaunch("teleop_twist_joy", "teleop.launch", f"joy_dev:={path}", "joy_config:=xbox")
    # the kernel's init burst, then the xbox enable button (2) and the stick pushed up
    send(
        fd,
        *(JoyEvent(0, 0, JS_EVENT_BUTTON | JS_EVENT_INIT, b) for b in range(6)),
        *(JoyEvent(0, 0, JS_EVENT_AXIS | JS_EVENT_INIT, a) for a in range(4)),
    )
    first = joys.wait_for(lambda m: len(m.buttons) == 6, timeout=30)
    assert first.header.frame_id == str(path) and list(first.axes) == [0.0] * 4
    send(fd, JoyEvent(1, -32767, JS_EVENT_AXIS, 1))
    joys.wait_for(lambda m: len(m.axes) > 1 and m.axes[1] > 0.99)
    assert not [t for t in twists.items if t.linear.x != 0.0]  # not enabled: no motion
    send(fd, JoyEvent(2, 1, JS_EVENT_BUTTON, 2))
    moving = twists.wait_for(lambda m: m.linear.x > 0.5)
    assert moving.linear.x == pytest.approx(0.7)  # scale_linear of xbox.config.yaml
    # autorepeat_rate 20 in teleop.launch: the held state keeps coming without events
    count = len(joys.items)
    time.sleep(0.5)
    assert len(joys.items) >= count + 5
    send(fd, JoyEvent(3, 0, JS_EVENT_BUTTON, 2))
    twists.wait_for(lambda m: m.linear.x == 0.0 and m.angular.z == 0.0)


def test_joy_node_retries_a_missing_device_and_reopens_when_it_comes_back(rig: Rig, tmp_path: Path) -> None:
    path = tmp_path / "js9"
    joys = rig.collect(rig.node("joy_test2"), "/joy", Joy)
    proc = rig.shipped("joy", "joy_node", f"_dev:={path}")
    out = rig.read_until(proc, "Couldn't open joystick")  # the device comes only after the first try
    os.mkfifo(path)
    fd = os.open(path, os.O_RDWR | os.O_NONBLOCK)
    try:
        send(fd, JoyEvent(0, 1, JS_EVENT_BUTTON, 0))
        joys.wait_for(lambda m: list(m.buttons) == [1], timeout=15)
    finally:
        os.close(fd)
    # the writer gone is the device unplugged: joy_node's line, once, and no busy reopening
    out += rig.read_until(proc, "Connection to joystick device lost unexpectedly. Will reopen.")
    time.sleep(1.5)
    out += rig.stop(proc)
    assert out.count(f"Couldn't open joystick {path}. Will retry every second.") == 1, out
    assert out.count("Connection to joystick device lost unexpectedly") == 1, out
    assert f"Opened joystick: {path} (Unknown). deadzone_: 0.050000." in out, out


@pytest.mark.ros1
def test_debian_rostopic_reads_joy_node(fifo, rig: Rig) -> None:  # noqa: ANN001
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    path, fd = fifo
    rig.shipped("joy", "joy_node", f"_dev:={path}", "_autorepeat_rate:=10", quiet=True)
    send(fd, JoyEvent(0, 16384, JS_EVENT_AXIS, 0), JoyEvent(0, 1, JS_EVENT_BUTTON, 1))
    out = subprocess.run(
        ["/usr/bin/rostopic", "echo", "-n", "1", "/joy"],
        env=testing.ros1_env(rig.uri),
        capture_output=True,
        text=True,
        timeout=30,
    ).stdout
    assert "buttons: [0, 1]" in out, out
    assert f'frame_id: "{path}"' in out, out
    assert "axes: [-0.47" in out, out  # (16384 - 1638.35) / 0.95 / 32767, sign flipped
