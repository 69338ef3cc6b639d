"""rospy_tutorials add_two_ints_client: ``add_two_ints_client [x y]`` calls ``add_two_ints`` and prints the sum.

Like the original it needs no init_node: a service client does not have to be a node.
"""

from __future__ import annotations

import random
import sys

from ninjemys.tutorials import node_main


def _usage(program: str) -> str:
    return "%s [x y]" % program


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy
    from rospy_tutorials.srv import AddTwoInts, AddTwoIntsRequest

    full = [sys.argv[0]] + (list(sys.argv[1:]) if argv is None else list(argv))
    args = rospy.myargv(full)
    if len(args) == 1:
        x, y = random.randint(-50000, 50000), random.randint(-50000, 50000)
    elif len(args) == 3:
        try:
            x, y = int(args[1]), int(args[2])
        except ValueError:
            print(_usage(args[0]))
            return 1
    else:
        print(_usage(args[0]))
        return 1
    rospy.wait_for_service("add_two_ints")
    proxy = rospy.ServiceProxy("add_two_ints", AddTwoInts)
    print("Requesting %s+%s" % (x, y))
    try:
        short = proxy(x, y)
        formal = proxy.call(AddTwoIntsRequest(x, y))
    except rospy.ServiceException as exc:
        print("Service call failed: %s" % exc)
        return 1
    if short.sum != x + y or formal.sum != x + y:
        print("Service call failed: returned sum was %s" % short.sum)
        return 1
    print("%s + %s = %s" % (x, y, short.sum))
    return 0


if __name__ == "__main__":
    sys.exit(main())
