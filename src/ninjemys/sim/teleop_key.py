"""``turtle_teleop_key``: drive turtle1 with the arrow keys, as ROS turtlesim's teleop node.

Node ``teleop_turtle`` publishes ``geometry_msgs/Twist`` on ``turtle1/cmd_vel`` (remappable) each time
an arrow key is pressed: up/down give ``linear.x = +-scale_linear``, left/right give
``angular.z = +-scale_angular`` (parameters ``~scale_linear``/``~scale_angular``, default 2.0). 'q'
quits. The terminal is switched to raw, unechoed input while it runs and always restored, also on
Ctrl-C or errors.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

from ninjemys.commands import entry

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ninjemys.node.node import Node

BANNER = "Reading from keyboard\n---------------------------\nUse arrow keys to move the turtle. 'q' to quit."

#: final byte of the arrow keys' escape sequences (ESC [ A ... ESC [ D, or ESC O A in keypad mode)
ARROWS = {b"A": "UP", b"B": "DOWN", b"C": "RIGHT", b"D": "LEFT"}


def twist_for(key: str, scale_linear: float, scale_angular: float) -> tuple[float, float] | None:
    """(linear.x, angular.z) for a key name, or None for keys that do nothing."""
    return {
        "UP": (scale_linear, 0.0),
        "DOWN": (-scale_linear, 0.0),
        "LEFT": (0.0, scale_angular),
        "RIGHT": (0.0, -scale_angular),
    }.get(key)


class KeyDecoder:
    """Turns raw terminal bytes into key names: ``UP``, ``DOWN``, ``LEFT``, ``RIGHT``, ``QUIT``.

    Escape sequences may arrive split across reads; the decoder keeps what it has not finished.
    """

    def __init__(self) -> None:
        self._pending = b""

    def feed(self, data: bytes) -> list[str]:
        keys = []
        buf = self._pending + data
        i = 0
        while i < len(buf):
            byte = buf[i : i + 1]
            if byte == b"\x1b":
                if i + 2 >= len(buf):
                    break  # incomplete sequence: wait for more bytes
                if buf[i + 1 : i + 2] in (b"[", b"O") and buf[i + 2 : i + 3] in ARROWS:
                    keys.append(ARROWS[buf[i + 2 : i + 3]])
                i += 3
                continue
            if byte in (b"q", b"Q"):
                keys.append("QUIT")
            elif byte == b"\x03":  # Ctrl-C while the terminal is raw (no SIGINT is generated)
                keys.append("QUIT")
            i += 1
        self._pending = buf[i:]
        return keys


@contextlib.contextmanager
def raw_terminal(fd: int) -> Iterator[None]:
    """Unbuffered, unechoed input on ``fd`` for the duration; a no-op when it is not a terminal."""
    if not os.isatty(fd):
        yield
        return
    import termios
    import tty

    saved = termios.tcgetattr(fd)
    try:
        tty.setcbreak(fd)
        mode = termios.tcgetattr(fd)
        mode[3] &= ~(termios.ECHO | termios.ICANON | termios.ISIG)
        termios.tcsetattr(fd, termios.TCSANOW, mode)
        yield
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def _scale(node: Node, name: str, default: float = 2.0) -> float:
    """A speed scale parameter; the default when it is unset, unusable or the master is away."""
    from ninjemys.errors import NinjemysError

    try:
        return float(node.get_param(name, default))
    except (NinjemysError, TypeError, ValueError) as exc:
        node.log.warn("%s: %s; using %.1f", name, exc, default)
        return default


def main(argv: list[str] | None = None) -> int:
    from geometry_msgs.msg import Twist
    from ninjemys.node.run import run_main

    def teleop(node: Node) -> None:
        scale_linear = _scale(node, "~scale_linear")
        scale_angular = _scale(node, "~scale_angular")
        pub = node.publisher("turtle1/cmd_vel", Twist, queue_size=1)
        print(BANNER, flush=True)
        fd = sys.stdin.fileno()
        decoder = KeyDecoder()
        with raw_terminal(fd):
            while not node.is_shutdown:
                try:
                    data = os.read(fd, 64)
                except InterruptedError:
                    continue
                if not data:  # end of input (stdin closed): stop like 'q'
                    return
                for key in decoder.feed(data):
                    if key == "QUIT":
                        return
                    motion = twist_for(key, scale_linear, scale_angular)
                    if motion is not None:
                        node.log.debug(key)
                        twist = Twist()
                        twist.linear.x, twist.angular.z = motion
                        pub.publish(twist)

    return run_main("teleop_turtle", argv, teleop)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
