"""roslaunch's Python API as ROS 1 scripts use it: ROSLaunchParent (launch files from a script),
scriptapi.ROSLaunch (single nodes), rlutil (run id, file arguments), core.Node, configure_logging.
The launching itself is ninjemys.launch's (the ``roslaunch`` command's)."""

from __future__ import annotations

import logging
import os
import socket
import sys

from ninjemys.roshome import log_directory

from . import core as core
from . import parent as parent
from . import rlutil as rlutil
from . import scriptapi as scriptapi
from .core import Node, RLException, add_printerrlog_handler, add_printlog_handler
from .parent import DEFAULT_TIMEOUT_SIGINT, DEFAULT_TIMEOUT_SIGTERM, NUM_WORKERS
from .scriptapi import ROSLaunch

__all__ = [
    "Node",
    "RLException",
    "ROSLaunch",
    "configure_logging",
    "main",
    "NAME",
    "DEFAULT_MASTER_PORT",
    "NUM_WORKERS",
    "DEFAULT_TIMEOUT_SIGINT",
    "DEFAULT_TIMEOUT_SIGTERM",
]

NAME = "roslaunch"
DEFAULT_MASTER_PORT = 11311


def configure_logging(uuid: str) -> None:
    """Log the ``roslaunch`` logger to ``<log dir>/<uuid>/roslaunch-<host>-<pid>.log`` (scripts using
    roslaunch call this first, as in ROS 1); a failure only warns."""
    try:
        path = log_directory() / uuid / f"{NAME}-{socket.gethostname()}-{os.getpid()}.log"
        path.parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(path)
        handler.setFormatter(logging.Formatter("[%(name)s][%(levelname)s] %(asctime)s: %(message)s"))
        logger = logging.getLogger(NAME)
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
        add_printlog_handler(logger.info)
        add_printerrlog_handler(logger.error)
        print(f"... logging to {path}")
    except OSError:
        print("WARNING: unable to configure logging. No log files will be generated", file=sys.stderr)


def main(argv: list[str] = sys.argv) -> None:
    """The ``roslaunch`` command with ``argv`` (``argv[0]`` is the program name), as ROS 1's entry point:
    our ``roslaunch`` runs it; a failure exits with its status."""
    import subprocess

    from ninjemys.commands import command_path

    code = subprocess.call([command_path("roslaunch"), *argv[1:]])
    if code:
        sys.exit(code)
