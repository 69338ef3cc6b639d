"""dynamic_reconfigure's exceptions (ROS 1 names; the facade re-exports them from the package root)."""

from __future__ import annotations

from ninjemys.errors import NinjemysError


class DynamicReconfigureException(NinjemysError):
    """Base of dynamic_reconfigure's errors."""


class DynamicReconfigureParameterException(DynamicReconfigureException):
    """A parameter is unknown to the server or its value cannot be converted to the parameter's type."""


class DynamicReconfigureCallbackException(DynamicReconfigureException):
    """The server's callback failed (returned None), or the set_parameters call failed."""


for _cls in (
    DynamicReconfigureException,
    DynamicReconfigureParameterException,
    DynamicReconfigureCallbackException,
):
    _cls.__module__ = "dynamic_reconfigure"
