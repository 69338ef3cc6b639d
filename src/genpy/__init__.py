"""genpy: ROS 1's Python message runtime as programs import it (``genpy.Message``, ``genpy.Time``,
the serialization errors), over ninjemys's generated message classes and rostime."""

from __future__ import annotations

from . import base as base  # reachable after a bare ``import genpy``, as in ROS 1
from .message import DeserializationError, Message, MessageException, SerializationError, struct_I
from .rostime import Duration, Time, TVal

__all__ = [
    "Time",
    "Duration",
    "TVal",
    "Message",
    "SerializationError",
    "DeserializationError",
    "MessageException",
    "struct_I",
]
