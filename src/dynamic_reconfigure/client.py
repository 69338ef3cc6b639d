"""ROS 1's ``dynamic_reconfigure.client.Client(name, timeout=None, config_callback=None)`` on rospy's node."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from dynamic_reconfigure._mapping import mapped
from ninjemys.dynamic_reconfigure.client import ReconfigureClient

__all__ = ["Client"]


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
