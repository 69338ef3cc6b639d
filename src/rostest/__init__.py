"""rostest, ROS 1's integration-test tool, as provided by ninjemys (``import rostest``).

A test node listed in a ``.test`` file's ``<test>`` tag ends with
``rostest.rosrun(PKG, 'name', TestCase)``; the ``rostest`` command starts the file's nodes on a
fresh master, runs each test node and gathers the results. Names and arguments follow rostest
1.15; the work is done by :mod:`ninjemys.rostest`.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

import rosgraph
import rospy
import rosunit
from ninjemys.rostest.pyunit import run as _run

__all__ = ["get_master", "is_publisher", "is_subscriber", "rosrun", "run", "unitrun"]

_GLOBAL_CALLER_ID = "/script"


def get_master() -> rosgraph.Master:
    """The master this process would talk to (ROS_MASTER_URI)."""
    return rosgraph.Master(_GLOBAL_CALLER_ID)


def _registered(topic: str, node: str, column: int) -> bool:
    state = get_master().getSystemState()
    for name, nodes in state[column]:
        if name == topic:
            return node in nodes
    return False


def is_subscriber(topic: str, subscriber_id: str) -> bool:
    """Whether node ``subscriber_id`` subscribes to ``topic`` (both as full graph names)."""
    return _registered(topic, subscriber_id, 1)


def is_publisher(topic: str, publisher_id: str) -> bool:
    """Whether node ``publisher_id`` publishes ``topic`` (both as full graph names)."""
    return _registered(topic, publisher_id, 0)


def rosrun(package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None) -> None:
    """Run a unittest-based test node: results to the file rostest names (``--gtest_output=xml:``,
    default ``~/.ros/test_results/<pkg>/rosunit-<name>.xml``), ``--text`` for unittest's own
    output; shuts the node down afterwards and exits 1 when a case failed."""
    ok = _run(package, test_name, test, sysargs)
    rospy.signal_shutdown("test complete")
    if not ok:
        sys.exit(1)


#: the older name of :func:`rosrun`
run = rosrun


def unitrun(
    package: str,
    test_name: str,
    test: Any,
    sysargs: Sequence[str] | None = None,
    coverage_packages: Sequence[str] | None = None,
) -> None:
    """rosunit.unitrun (deprecated in rostest, as in ROS 1)."""
    import warnings

    warnings.warn("Call to deprecated function unitrun.", DeprecationWarning, stacklevel=2)
    rosunit.unitrun(package, test_name, test, sysargs=sysargs, coverage_packages=coverage_packages)
