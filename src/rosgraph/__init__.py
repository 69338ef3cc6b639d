"""rosgraph: the ROS 1 graph's Python API (master handle, names, environment, network helpers) as
programs and test harnesses import it, over ninjemys's master client and name functions."""

from __future__ import annotations

import sys
from collections.abc import Sequence

from . import names
from . import network as network  # reachable after a bare ``import rosgraph``, as in ROS 1
from .masterapi import Master, MasterError, MasterException, MasterFailure
from .masterapi import is_online as is_master_online
from .rosenv import ROS_HOSTNAME, ROS_IP, ROS_IPV6, ROS_MASTER_URI, ROS_NAMESPACE, get_master_uri


def myargv(argv: Sequence[str] | None = None) -> list[str]:
    """``argv`` (default sys.argv) without the ``from:=to`` remapping arguments."""
    if argv is None:
        argv = sys.argv
    return [a for a in argv if names.REMAP not in a]


__all__ = [
    "myargv",
    "get_master_uri",
    "ROS_MASTER_URI",
    "ROS_NAMESPACE",
    "ROS_HOSTNAME",
    "ROS_IP",
    "ROS_IPV6",
    "Master",
    "MasterFailure",
    "MasterError",
    "MasterException",
    "is_master_online",
]
