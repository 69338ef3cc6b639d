"""ROS 1's ``dynamic_reconfigure.server.Server(type, callback, namespace="")`` on rospy's node."""

from __future__ import annotations

from typing import Any

from dynamic_reconfigure import DynamicReconfigureCallbackException
from dynamic_reconfigure._mapping import mapped
from dynamic_reconfigure.encoding import (
    decode_config,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    initial_config,
)
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv
from ninjemys.dynamic_reconfigure.server import Callback, ReconfigureServer

__all__ = [
    "ConfigDescrMsg",
    "ConfigMsg",
    "DynamicReconfigureCallbackException",
    "ReconfigureSrv",
    "Server",
    "decode_config",
    "encode_config",
    "encode_description",
    "extract_params",
    "get_tree",
    "initial_config",
]


class Server(ReconfigureServer):
    """Serve the generated ``type`` (``from my_pkg.cfg import FooConfig``) on the node ``init_node`` made."""

    def __init__(self, type: Any, callback: Callback, namespace: str = "") -> None:
        import rospy

        with mapped():
            super().__init__(rospy.core.process_node(), type, callback, namespace)

    def update_configuration(self, changes: Any) -> Any:
        with mapped():
            return super().update_configuration(changes)
