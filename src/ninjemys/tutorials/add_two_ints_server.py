"""rospy_tutorials add_two_ints_server: serve ``add_two_ints`` (rospy_tutorials/AddTwoInts)."""

from __future__ import annotations

import sys
from typing import Any

from ninjemys.tutorials import node_main


def _add(request: Any) -> Any:
    from rospy_tutorials.srv import AddTwoIntsResponse

    total = request.a + request.b
    print("Returning [%s + %s = %s]" % (request.a, request.b, total), flush=True)
    return AddTwoIntsResponse(total)


@node_main
def main(argv: list[str] | None = None) -> int:
    import rospy
    from rospy_tutorials.srv import AddTwoInts

    if argv is not None:
        sys.argv[1:] = argv
    rospy.init_node("add_two_ints_server")
    rospy.Service("add_two_ints", AddTwoInts, _add)
    print("Ready to add two ints.", flush=True)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
