"""Where ROS 1 keeps its files: the log directory rule shared by roscore, roslaunch and every node.

A leaf module (stdlib only): roscore imports it at start-up, before anything heavy.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path


def log_directory(env: Mapping[str, str] | None = None) -> Path:
    """ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log (rospkg.get_log_dir's rule)."""
    env = os.environ if env is None else env
    if env.get("ROS_LOG_DIR"):
        return Path(env["ROS_LOG_DIR"])
    if env.get("ROS_HOME"):
        return Path(env["ROS_HOME"]) / "log"
    return Path.home() / ".ros" / "log"
