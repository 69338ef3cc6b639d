"""ROS 1's ``dynamic_reconfigure`` Python package, as a facade over :mod:`ninjemys.dynamic_reconfigure`.

``dynamic_reconfigure.msg`` / ``.srv`` are the lazy interface modules; ``server.Server``,
``client.Client``, ``encoding`` and ``parameter_generator_catkin`` are ROS 1's modules of the same
names. The exception classes and the two helpers below are what ROS 1's package root offers.
"""

from __future__ import annotations

from typing import Any

from ninjemys.dynamic_reconfigure.errors import (
    DynamicReconfigureCallbackException,
    DynamicReconfigureException,
    DynamicReconfigureParameterException,
)

__all__ = [
    "DynamicReconfigureCallbackException",
    "DynamicReconfigureException",
    "DynamicReconfigureParameterException",
    "find_reconfigure_services",
    "get_parameter_names",
]


def find_reconfigure_services() -> list[str]:
    """Every node offering ``<node>/set_parameters``, sorted (what ``dynparam list`` prints)."""
    import rospy
    from ninjemys.dynamic_reconfigure.client import reconfigure_servers

    return reconfigure_servers(rospy.core.process_node())


def get_parameter_names(descr: Any) -> Any:
    """The parameter names of a generated ``<Name>Config`` module."""
    return descr.defaults.keys()
