"""The rospy_tutorials programs shipped with ninjemys: ``rosrun rospy_tutorials talker.py`` and friends.

Each module is an executable node with ``main(argv) -> int`` written against the rospy API, so the
classic tutorial commands (talker/listener, add_two_ints server/client) work right after
``pip install``; the packages layer maps ``rosrun rospy_tutorials <name>`` to these modules.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Protocol

    class Main(Protocol):
        """A tutorial's ``main``: called with no arguments by its console script, with argv by rosrun."""

        def __call__(self, argv: list[str] | None = None) -> int: ...


def node_main(body: Callable[[list[str] | None], int]) -> Main:
    """Wrap a tutorial's ``main``: a start-up problem (bad ``_param:=``, bad ``__name:=``, no master for a
    client) is one ``ERROR:`` line on stderr and exit code 1, never a traceback."""

    @functools.wraps(body)
    def main(argv: list[str] | None = None) -> int:
        import rospy

        try:
            return body(argv)
        except (rospy.ROSInitException, ValueError) as exc:
            print(f"ERROR: {exc}", file=sys.stderr)
            return 1

    return main


#: rosrun executable name -> module under ninjemys.tutorials
EXECUTABLES = {
    "talker": "talker",
    "talker.py": "talker",
    "listener": "listener",
    "listener.py": "listener",
    "add_two_ints_server": "add_two_ints_server",
    "add_two_ints_server.py": "add_two_ints_server",
    "add_two_ints_client": "add_two_ints_client",
    "add_two_ints_client.py": "add_two_ints_client",
}
