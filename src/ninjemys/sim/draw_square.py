"""``draw_square``: ROS turtlesim's tutorial that resets the sim and drives turtle1 around 2 m squares.

A pose-feedback state machine at the turtlesim rate: forward until within 0.1 of the goal, wait until
stopped, turn 90 degrees at 0.4 rad/s until within 0.01 rad, wait until stopped, next side.
"""

from __future__ import annotations

import math
import threading
from enum import Enum

from ninjemys.commands import entry

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ninjemys.node.node import Node

SIDE = 2.0
FORWARD_SPEED = 1.0
TURN_SPEED = 0.4


class State(Enum):
    FORWARD = 0
    STOP_FORWARD = 1
    TURN = 2
    STOP_TURN = 3


class SquareController:
    """Decides the next (linear, angular) command from the latest pose; pure, so tests can drive it."""

    def __init__(self) -> None:
        self.state: State | None = None
        self.goal: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.goals: list[tuple[float, float, float]] = []

    def _set_goal(self, x: float, y: float, theta: float) -> None:
        self.goal = (x, y, theta)
        self.goals.append(self.goal)

    def reached(self, pose) -> bool:  # type: ignore[no-untyped-def]
        gx, gy, gt = self.goal
        return abs(pose.x - gx) < 0.1 and abs(pose.y - gy) < 0.1 and abs(pose.theta - gt) < 0.01

    @staticmethod
    def stopped(pose) -> bool:  # type: ignore[no-untyped-def]
        return abs(pose.angular_velocity) < 0.0001 and abs(pose.linear_velocity) < 0.0001

    def step(self, pose) -> tuple[float, float]:  # type: ignore[no-untyped-def]
        if self.state is None:
            self.state = State.FORWARD
            self._set_goal(
                pose.x + math.cos(pose.theta) * SIDE, pose.y + math.sin(pose.theta) * SIDE, pose.theta
            )
        match self.state:
            case State.FORWARD:
                if self.reached(pose):
                    self.state = State.STOP_FORWARD
                    return 0.0, 0.0
                return FORWARD_SPEED, 0.0
            case State.STOP_FORWARD:
                if self.stopped(pose):
                    self.state = State.TURN
                    theta = math.remainder(self.goal[2] + math.pi / 2, 2 * math.pi)
                    self._set_goal(self.goal[0], self.goal[1], theta)
                return 0.0, 0.0
            case State.TURN:
                if self.reached(pose):
                    self.state = State.STOP_TURN
                    return 0.0, 0.0
                return 0.0, TURN_SPEED
            case State.STOP_TURN:
                if self.stopped(pose):
                    self.state = State.FORWARD
                    self._set_goal(
                        pose.x + math.cos(pose.theta) * SIDE, pose.y + math.sin(pose.theta) * SIDE, pose.theta
                    )
                return 0.0, 0.0
        return 0.0, 0.0


def main(argv: list[str] | None = None) -> int:
    from geometry_msgs.msg import Twist
    from ninjemys.node.run import run_main
    from std_srvs.srv import Empty
    from turtlesim.msg import Pose

    def drive(node: Node) -> None:
        controller = SquareController()
        latest: list[Pose] = []
        lock = threading.Lock()

        def on_pose(msg: Pose) -> None:
            with lock:
                latest[:] = [msg]

        pub = node.publisher("turtle1/cmd_vel", Twist, queue_size=1)
        node.subscriber("turtle1/pose", Pose, on_pose, queue_size=1)
        node.wait_for_service("reset")
        node.service_proxy("reset", Empty)()
        rate = node.rate(1 / 0.016)
        reported = 0
        while not node.is_shutdown:
            with lock:
                pose = latest[0] if latest else None
            if pose is not None:
                linear, angular = controller.step(pose)
                for goal in controller.goals[reported:]:
                    node.log.info("New goal [%f %f, %f]", *goal)
                reported = len(controller.goals)
                twist = Twist()
                twist.linear.x, twist.angular.z = linear, angular
                pub.publish(twist)
            rate.sleep()  # ShutdownError ends the loop (run_main ends the node quietly)

    return run_main("draw_square", argv, drive)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
