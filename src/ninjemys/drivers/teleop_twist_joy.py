"""``rosrun teleop_twist_joy teleop_node``: ``sensor_msgs/Joy`` to ``geometry_msgs/Twist``, as ROS 1's.

While the enable button is held, ``cmd_vel`` carries the configured axes times their scales (the
turbo button, when set and held, takes precedence with the turbo scales); when neither is held, one
zero Twist goes out so the robot stops, then nothing. ``cmd_vel`` is latched, queue 1.

Parameters (private, as teleop_twist_joy reads them): ``~enable_button`` (0),
``~enable_turbo_button`` (-1: none); ``~axis_linear`` either an int (the ``x`` axis, default 1) with
``~scale_linear`` (0.5) and ``~scale_linear_turbo`` (1.0), or a map ``{x, y, z: axis}`` with maps of
scales; ``~axis_angular`` an int (``yaw``, default 0) with ``~scale_angular`` (0.5) and
``~scale_angular_turbo`` (defaults to the normal scale), or a map ``{yaw, pitch, roll: axis}``. ``~require_enable_button`` (true) is the ROS 2 port's switch,
read so that its config files work: false drives with the normal scales without holding a button
(ROS 1's node has no such parameter and always requires the button). An axis
or button beyond the message's arrays reads as 0 / not pressed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ninjemys.idl.loader import get_message_class
from ninjemys.node.run import run_node


def _msg(type_name: str) -> Any:
    """A message class, typed loosely: its fields are generated at run time."""
    return get_message_class(type_name)


LINEAR = ("x", "y", "z")
ANGULAR = ("yaw", "pitch", "roll")


@dataclass
class TeleopConfig:
    enable_button: int = 0
    enable_turbo_button: int = -1
    axis_linear: dict[str, int] | None = None
    scale_linear: dict[str, dict[str, float]] | None = None  # "normal"/"turbo" -> field -> scale
    axis_angular: dict[str, int] | None = None
    scale_angular: dict[str, dict[str, float]] | None = None
    require_enable_button: bool = True


def read_config(get: Any) -> TeleopConfig:
    """The configuration from ``get(name, default)`` (private parameters), as the C++ node reads it."""
    missing = object()
    config = TeleopConfig(int(get("~enable_button", 0)), int(get("~enable_turbo_button", -1)))
    config.require_enable_button = bool(get("~require_enable_button", True))
    axis = get("~axis_linear", missing)
    if isinstance(axis, dict):
        config.axis_linear = {str(k): int(v) for k, v in axis.items()}
        config.scale_linear = {
            "normal": _scales(get("~scale_linear", {})),
            "turbo": _scales(get("~scale_linear_turbo", {})),
        }
    else:
        config.axis_linear = {"x": int(axis) if axis is not missing else 1}
        config.scale_linear = {
            "normal": {"x": float(get("~scale_linear", 0.5))},
            "turbo": {"x": float(get("~scale_linear_turbo", 1.0))},
        }
    axis = get("~axis_angular", missing)
    if isinstance(axis, dict):
        config.axis_angular = {str(k): int(v) for k, v in axis.items()}
        config.scale_angular = {
            "normal": _scales(get("~scale_angular", {})),
            "turbo": _scales(get("~scale_angular_turbo", {})),
        }
    else:
        normal = float(get("~scale_angular", 0.5))
        config.axis_angular = {"yaw": int(axis) if axis is not missing else 0}
        config.scale_angular = {
            "normal": {"yaw": normal},
            "turbo": {"yaw": float(get("~scale_angular_turbo", normal))},
        }
    return config


def _scales(value: Any) -> dict[str, float]:
    return {str(k): float(v) for k, v in value.items()} if isinstance(value, dict) else {}


class Teleop:
    """The mapping, without a node: ``on_joy`` returns the Twist to send, or None."""

    def __init__(self, config: TeleopConfig, twist_class: Any) -> None:
        self.config = config
        self.Twist = twist_class
        self.sent_disable = False

    @staticmethod
    def _held(buttons: Any, index: int) -> bool:
        return 0 <= index < len(buttons) and bool(buttons[index])

    def on_joy(self, axes: Any, buttons: Any) -> Any:
        c = self.config
        if c.enable_turbo_button >= 0 and self._held(buttons, c.enable_turbo_button):
            return self._twist(axes, "turbo")
        if not c.require_enable_button or self._held(buttons, c.enable_button):
            return self._twist(axes, "normal")
        if not self.sent_disable:
            self.sent_disable = True
            return self.Twist()
        return None

    def _twist(self, axes: Any, which: str) -> Any:
        c = self.config
        assert c.axis_linear is not None and c.scale_linear is not None
        assert c.axis_angular is not None and c.scale_angular is not None
        msg = self.Twist()
        for name in LINEAR:
            setattr(msg.linear, name, _value(axes, c.axis_linear, c.scale_linear[which], name))
        for name, field in zip(ANGULAR, ("z", "y", "x"), strict=True):
            setattr(msg.angular, field, _value(axes, c.axis_angular, c.scale_angular[which], name))
        self.sent_disable = False
        return msg


def _value(axes: Any, axis_map: dict[str, int], scale_map: dict[str, float], name: str) -> float:
    if name not in axis_map or name not in scale_map or not 0 <= axis_map[name] < len(axes):
        return 0.0
    return float(axes[axis_map[name]]) * scale_map[name]


def start(node: Any) -> Teleop:
    """The node's publisher, subscriber and log lines (as the C++ node prints them)."""
    config = read_config(node.get_param)
    teleop = Teleop(config, _msg("geometry_msgs/Twist"))
    pub = node.publisher("cmd_vel", teleop.Twist, queue_size=1, latch=True)
    log = node.log
    log.info("Teleop enable button %i.", config.enable_button)
    turbo = config.enable_turbo_button >= 0
    if turbo:
        log.info("Turbo on button %i.", config.enable_turbo_button)
    for kind, axes, scales in (
        ("Linear", config.axis_linear, config.scale_linear),
        ("Angular", config.axis_angular, config.scale_angular),
    ):
        assert axes is not None and scales is not None
        for name, index in sorted(axes.items()):
            log.info("%s axis %s on %i at scale %f.", kind, name, index, scales["normal"].get(name, 0.0))
            if turbo:
                log.info(
                    "Turbo for %s axis %s is scale %f.", kind.lower(), name, scales["turbo"].get(name, 0.0)
                )

    def on_joy(msg: Any) -> None:
        twist = teleop.on_joy(msg.axes, msg.buttons)
        if twist is not None:
            pub.publish(twist)

    node.subscriber("joy", _msg("sensor_msgs/Joy"), on_joy, queue_size=1)
    return teleop


def main(argv: list[str] | None = None) -> int:
    """``rosrun teleop_twist_joy teleop_node``."""
    return run_node("teleop_twist_joy_node", argv, start)
