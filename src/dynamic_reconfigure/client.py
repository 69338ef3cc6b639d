"""ROS 1's ``dynamic_reconfigure.client.Client(name, timeout=None, config_callback=None)`` on rospy's node."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from dynamic_reconfigure import DynamicReconfigureCallbackException, DynamicReconfigureParameterException
from dynamic_reconfigure._mapping import mapped
from dynamic_reconfigure.encoding import decode_config, decode_description, encode_config, extract_params
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv
from ninjemys.dynamic_reconfigure.client import ReconfigureClient
from rospy.service import ServiceException

__all__ = [
    "Client",
    "ConfigDescrMsg",
    "ConfigMsg",
    "DynamicReconfigureCallbackException",
    "DynamicReconfigureParameterException",
    "ReconfigureSrv",
    "ServiceException",
    "decode_config",
    "decode_description",
    "encode_config",
    "extract_params",
]


class Client(ReconfigureClient):
    """Follow and change the configuration of the dynamic_reconfigure server ``name``.

    A ``timeout`` that runs out while waiting for the server raises ``rospy.ROSException``, as ROS 1.
    """

    def __init__(
        self,
        name: str,
        timeout: float | None = None,
        config_callback: Callable[[Any], Any] | None = None,
        description_callback: Callable[[Any], Any] | None = None,
    ) -> None:
        import rospy

        with mapped():
            super().__init__(rospy.core.process_node(), name, timeout, config_callback, description_callback)

    def update_configuration(self, changes: dict[str, Any]) -> Any:
        with mapped():
            return super().update_configuration(changes)
