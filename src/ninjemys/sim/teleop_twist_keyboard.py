"""``rosrun teleop_twist_keyboard teleop_twist_keyboard.py``: the ROS keyboard teleop for ``cmd_vel``.

Same keys, parameters and printed text as the ROS package: ``u i o / j k l / m , .`` move (shifted:
holonomic), ``t``/``b`` up/down, ``q/z w/x e/c`` scale the speeds by 10 %, anything else stops,
Ctrl-C quits. Parameters ``~speed`` (0.5), ``~turn`` (1.0), ``~speed_limit``/``~turn_limit`` (1000),
``~repeat_rate`` (0: publish on key presses only), ``~key_timeout`` (seconds without a key that stop the
robot; 0, the default, disables), ``~stamped`` (publish geometry_msgs/TwistStamped) and ``~frame_id``. It waits
for a subscriber on ``cmd_vel`` first, printing ``Waiting for subscriber to connect to /cmd_vel``
every 2.5 s as the original does, and publishes a zero twist on exit.
"""

from __future__ import annotations

import os
import select
import sys
import time

from ninjemys.commands import entry
from ninjemys.sim.teleop_key import raw_terminal

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ninjemys.node.node import Node

BANNER = """
Reading from the keyboard  and Publishing to Twist!
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

For Holonomic mode (strafing), hold down the shift key:
---------------------------
   U    I    O
   J    K    L
   M    <    >

t : up (+z)
b : down (-z)

anything else : stop

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%

CTRL-C to quit
"""

#: key -> (x, y, z, th) directions
MOVE_BINDINGS: dict[str, tuple[int, int, int, int]] = {
    "i": (1, 0, 0, 0),
    "o": (1, 0, 0, -1),
    "j": (0, 0, 0, 1),
    "l": (0, 0, 0, -1),
    "u": (1, 0, 0, 1),
    ",": (-1, 0, 0, 0),
    ".": (-1, 0, 0, 1),
    "m": (-1, 0, 0, -1),
    "O": (1, -1, 0, 0),
    "I": (1, 0, 0, 0),
    "J": (0, 1, 0, 0),
    "L": (0, -1, 0, 0),
    "U": (1, 1, 0, 0),
    "<": (-1, 0, 0, 0),
    ">": (-1, -1, 0, 0),
    "M": (-1, 1, 0, 0),
    "t": (0, 0, 1, 0),
    "b": (0, 0, -1, 0),
}

#: key -> (linear factor, angular factor)
SPEED_BINDINGS: dict[str, tuple[float, float]] = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1.0),
    "x": (0.9, 1.0),
    "e": (1.0, 1.1),
    "c": (1.0, 0.9),
}


def vels(speed: float, turn: float) -> str:
    return f"currently:\tspeed {speed}\tturn {turn} "


class TeleopState:
    """The key logic, separate from the terminal: feed keys, read the twist to publish."""

    def __init__(self, speed: float, turn: float, speed_limit: float, turn_limit: float) -> None:
        self.speed, self.turn = speed, turn
        self.speed_limit, self.turn_limit = speed_limit, turn_limit
        self.x = self.y = self.z = self.th = 0
        self.status = 0

    def key(self, key: str) -> list[str]:
        """Apply one key; returns the lines to print."""
        out: list[str] = []
        if key in MOVE_BINDINGS:
            self.x, self.y, self.z, self.th = MOVE_BINDINGS[key]
        elif key in SPEED_BINDINGS:
            self.speed = min(self.speed_limit, self.speed * SPEED_BINDINGS[key][0])
            self.turn = min(self.turn_limit, self.turn * SPEED_BINDINGS[key][1])
            if self.speed == self.speed_limit:
                out.append("Linear speed limit reached!")
            if self.turn == self.turn_limit:
                out.append("Angular speed limit reached!")
            out.append(vels(self.speed, self.turn))
            if self.status == 14:
                out.append(BANNER)
            self.status = (self.status + 1) % 15
        else:
            self.stop()
        return out

    def stop(self) -> None:
        self.x = self.y = self.z = self.th = 0

    def twist(self) -> tuple[float, float, float, float]:
        """(linear.x, linear.y, linear.z, angular.z)."""
        return self.x * self.speed, self.y * self.speed, self.z * self.speed, self.th * self.turn


def main(argv: list[str] | None = None) -> int:
    from ninjemys.node.run import run_main

    return run_main("teleop_twist_keyboard", argv, _teleop)


def _teleop(node: Node) -> int:
    from geometry_msgs.msg import Twist, TwistStamped
    from ninjemys.errors import NinjemysError

    def param(name: str, default: float | bool | str) -> float | bool | str:
        try:
            return node.get_param("~" + name, default)
        except NinjemysError as exc:
            node.log.warn("~%s: %s; using %r", name, exc, default)
            return default

    try:
        state = TeleopState(
            float(param("speed", 0.5)),
            float(param("turn", 1.0)),
            float(param("speed_limit", 1000)),
            float(param("turn_limit", 1000)),
        )
        repeat = float(param("repeat_rate", 0.0))
        key_timeout = float(param("key_timeout", 0.0))
    except (TypeError, ValueError) as exc:
        print(f"teleop_twist_keyboard: bad parameter: {exc}", file=sys.stderr)
        return 1
    stamped = bool(param("stamped", False))
    frame_id = str(param("frame_id", ""))
    pub = node.publisher("cmd_vel", TwistStamped if stamped else Twist, queue_size=1)

    def publish() -> None:
        lx, ly, lz, az = state.twist()
        msg = TwistStamped() if stamped else Twist()
        twist = msg.twist if stamped else msg
        if stamped:
            msg.header.stamp = node.now()
            msg.header.frame_id = frame_id
        twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.z = lx, ly, lz, az
        pub.publish(msg)

    i = 0
    while not node.is_shutdown and pub.get_num_connections() == 0:
        if i == 4:
            print(f"Waiting for subscriber to connect to {pub.resolved_name}", flush=True)
        time.sleep(0.5)
        i = (i + 1) % 5
    if node.is_shutdown:
        return 1
    print(BANNER, flush=True)
    print(vels(state.speed, state.turn), flush=True)
    fd = sys.stdin.fileno()
    period = 1.0 / repeat if repeat > 0 else None  # the original's publishing thread
    timeout = key_timeout if key_timeout > 0 else None
    last_key = last_pub = time.monotonic()
    try:
        with raw_terminal(fd):
            while not node.is_shutdown:
                now = time.monotonic()
                deadlines = []
                if timeout is not None and state.twist() != (0.0, 0.0, 0.0, 0.0):
                    deadlines.append(last_key + timeout)
                if period is not None:
                    deadlines.append(last_pub + period)
                wait = max(0.0, min(deadlines) - now) if deadlines else None
                ready, _, _ = select.select([fd], [], [], wait)
                now = time.monotonic()
                if not ready:
                    if (
                        timeout is not None
                        and now - last_key >= timeout
                        and state.twist() != (0.0, 0.0, 0.0, 0.0)
                    ):
                        state.stop()  # no key for key_timeout: stop the robot
                    publish()
                    last_pub = now
                    continue
                data = os.read(fd, 16)
                if not data:
                    break
                last_key = now
                for ch in data.decode("utf-8", "replace"):  # keys typed ahead arrive in one read
                    if ch == "\x03":
                        return 0
                    for line in state.key(ch):
                        print(line, flush=True)
                    publish()  # one Twist per key, as the original's read-one-key loop
                last_pub = now
    finally:
        state.stop()
        if not node.is_shutdown:
            publish()
    return 0


console_main = entry(main)

if __name__ == "__main__":
    console_main()
