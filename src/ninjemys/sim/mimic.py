"""``mimic``: ROS turtlesim's tutorial node that makes one turtle copy another's motion.

Subscribes ``input/pose`` and publishes ``output/cmd_vel`` with the same linear and angular speed;
remap both (``input:=turtle1 output:=turtle2``) to pair two turtles.
"""

from __future__ import annotations

from ninjemys.commands import entry

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ninjemys.node.node import Node


def twist_from_pose(pose, twist_class):  # type: ignore[no-untyped-def]
    """The command that reproduces a pose's motion."""
    twist = twist_class()
    twist.linear.x = pose.linear_velocity
    twist.angular.z = pose.angular_velocity
    return twist


def main(argv: list[str] | None = None) -> int:
    from geometry_msgs.msg import Twist
    from ninjemys.node.run import run_node
    from turtlesim.msg import Pose

    def build(node: Node) -> None:
        pub = node.publisher("output/cmd_vel", Twist, queue_size=1)
        node.subscriber(
            "input/pose", Pose, lambda pose: pub.publish(twist_from_pose(pose, Twist)), queue_size=1
        )

    return run_node("turtle_mimic", argv, build)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
