"""``roslib.message``: message and service classes by type name (``"std_msgs/String"``)."""

from __future__ import annotations

from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl import loader

__all__ = ["get_message_class", "get_service_class"]


def get_message_class(message_type: str, reload_on_error: bool = False) -> Any:
    """The class of ``message_type``, or None when no package defines it."""
    try:
        return loader.get_message_class(message_type)
    except (NinjemysError, ValueError):
        return None


def get_service_class(service_type: str, reload_on_error: bool = False) -> Any:
    """The class of ``service_type``, or None when no package defines it."""
    try:
        return loader.get_service_class(service_type)
    except (NinjemysError, ValueError):
        return None
