"""rosgraph.rosenv: the ROS environment variables and the master URI a process uses (the
``__master:=`` argument first, then ROS_MASTER_URI, then ROS 1's default)."""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, Sequence

ROS_MASTER_URI = "ROS_MASTER_URI"
ROS_IP = "ROS_IP"
ROS_IPV6 = "ROS_IPV6"
ROS_HOSTNAME = "ROS_HOSTNAME"
ROS_NAMESPACE = "ROS_NAMESPACE"

DEFAULT_MASTER_PORT = 11311
DEFAULT_MASTER_URI = f"http://localhost:{DEFAULT_MASTER_PORT}/"


def get_master_uri(env: Mapping[str, str] | None = None, argv: Sequence[str] | None = None) -> str:
    """The master URI: ``__master:=URI`` on the command line wins over ROS_MASTER_URI (as in ROS 1,
    a malformed ``__master:=`` is a ValueError rather than a silent fallback)."""
    env = os.environ if env is None else env
    argv = sys.argv if argv is None else argv
    for arg in argv:
        if arg.startswith("__master:="):
            parts = arg.split(":=")
            if len(parts) != 2 or not parts[1]:
                raise ValueError(f"__master remapping argument '{arg}' improperly specified")
            return parts[1]
    return env.get(ROS_MASTER_URI, DEFAULT_MASTER_URI)
