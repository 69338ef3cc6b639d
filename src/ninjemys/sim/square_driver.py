"""``square_driver``: drive turtle1 around a 1 m square by dead reckoning, as in the PuzzleBot activity.

The turtle stands in for a differential-drive robot with wheel radius r = 0.05 m and wheel separation
l = 0.18 m. Each loop picks wheel speeds (w_r, w_l), commands the body velocity they produce, and
integrates what that covered over the measured loop time dt (the node's ROS time)::

    d     = r * (w_r + w_l) / 2 * dt        distance moved
    theta = r * (w_r - w_l) / l * dt        angle turned

A side ends when the distance reaches 1 m, a corner when the angle reaches 90 degrees.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass

from ninjemys.commands import entry

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ninjemys.node.node import Node

WHEEL_RADIUS = 0.05
WHEEL_SEPARATION = 0.18


@dataclass
class DiffDrive:
    """Wheel speeds -> body velocity, and the seed's distance/angle increments."""

    r: float = WHEEL_RADIUS
    l: float = WHEEL_SEPARATION  # noqa: E741 - the seed's symbol

    def linear(self, w_r: float, w_l: float) -> float:
        return self.r * (w_r + w_l) / 2.0

    def angular(self, w_r: float, w_l: float) -> float:
        return self.r * (w_r - w_l) / self.l

    def distance(self, w_r: float, w_l: float, dt: float) -> float:
        return self.linear(w_r, w_l) * dt

    def angle(self, w_r: float, w_l: float, dt: float) -> float:
        return self.angular(w_r, w_l) * dt


class SquarePlan:
    """Sides and corners of the square; ``step(dt)`` returns the wheel speeds for the next interval."""

    def __init__(self, side: float = 1.0, wheel_speed: float = 6.0, turn_speed: float = 3.0) -> None:
        self.side = side
        self.wheel_speed = wheel_speed
        self.turn_speed = turn_speed
        self.drive = DiffDrive()
        self.turning = False
        self.covered = 0.0  # metres along this side, or radians through this corner
        self.legs = 0  # sides plus corners completed

    def wheels(self) -> tuple[float, float]:
        if self.turning:
            return self.turn_speed, -self.turn_speed
        return self.wheel_speed, self.wheel_speed

    def advance(self, w_r: float, w_l: float, dt: float) -> bool:
        """Account for ``dt`` seconds at the given wheel speeds; True when the side or corner is done."""
        if self.turning:
            self.covered += self.drive.angle(w_r, w_l, dt)
            done = self.covered >= math.pi / 2
        else:
            self.covered += self.drive.distance(w_r, w_l, dt)
            done = self.covered >= self.side
        if done:
            self.turning = not self.turning
            self.covered = 0.0
            self.legs += 1
        return done


def main(argv: list[str] | None = None) -> int:
    from geometry_msgs.msg import Twist
    from ninjemys.errors import ShutdownError
    from ninjemys.node.run import run_main

    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="square_driver", description=__doc__.split("\n")[0])
    parser.add_argument("--side", type=float, default=1.0, help="side length in metres (default 1)")
    parser.add_argument("--laps", type=int, default=0, help="squares to drive (default: until Ctrl-C)")
    options = parser.parse_args([a for a in argv if ":=" not in a])

    def drive(node: Node) -> None:
        pub = node.publisher("turtle1/cmd_vel", Twist, queue_size=1)
        plan = SquarePlan(options.side)
        rate = node.rate(50)
        # dead reckoning counts every command as driven: do not start before turtlesim is listening
        while pub.get_num_connections() == 0 and not node.is_shutdown:
            rate.sleep()  # ShutdownError ends the node quietly (run_main)
        node.log.info(
            "Driving a %.2f m square (r=%.2f m, l=%.2f m)", plan.side, WHEEL_RADIUS, WHEEL_SEPARATION
        )
        last = node.get_time()
        w_r, w_l = plan.wheels()
        try:
            while not node.is_shutdown:
                now = node.get_time()
                if plan.advance(w_r, w_l, now - last):
                    node.log.info("%s done", "side" if plan.turning else "corner")
                    if options.laps and plan.legs >= 8 * options.laps:
                        break
                last = now
                w_r, w_l = plan.wheels()
                twist = Twist()
                twist.linear.x = plan.drive.linear(w_r, w_l)
                twist.angular.z = plan.drive.angular(w_r, w_l)
                pub.publish(twist)
                rate.sleep()
        except ShutdownError:
            pass
        pub.publish(Twist())

    return run_main("square_driver", [a for a in argv if ":=" in a], drive)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
