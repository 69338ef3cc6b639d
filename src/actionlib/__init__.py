"""``import actionlib``: ROS 1's action library, over :mod:`ninjemys.actionlib`.

As in ROS 1 the package exposes everything of ``actionlib.action_client``,
``actionlib.simple_action_client``, ``actionlib.action_server`` and ``actionlib.simple_action_server``
(``actionlib.SimpleActionClient``, ``actionlib.GoalStatus``, ``actionlib.CommState`` ...). Names are
resolved on first use, so ``import actionlib`` itself loads nothing. The classes run on the node
``rospy.init_node()`` made.

``actionlib.msg`` is also here: the interface package of actionlib's test actions (Test, TestRequest,
TwoInts), a lazy module whose definitions live in ``ninjemys/interfaces/actionlib/``.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

#: public name -> the facade module that defines it (ROS 1's star imports, made lazy)
_EXPORTS = {
    "ActionClient": "action_client",
    "ClientGoalHandle": "action_client",
    "CommState": "action_client",
    "CommStateMachine": "action_client",
    "TerminalState": "action_client",
    "GoalManager": "action_client",
    "get_name_of_constant": "action_client",
    "GoalStatus": "action_client",
    "GoalID": "action_client",
    "GoalStatusArray": "action_client",
    "Header": "action_client",
    "NO_TRANSITION": "action_client",
    "INVALID_TRANSITION": "action_client",
    "HandleTrackerDeleter": "handle_tracker_deleter",
    "ActionException": "exceptions",
    "SimpleActionClient": "simple_action_client",
    "SimpleGoalState": "simple_action_client",
    "ActionServer": "action_server",
    "ServerGoalHandle": "server_goal_handle",
    "StatusTracker": "status_tracker",
    "GoalIDGenerator": "goal_id_generator",
    "nop_cb": "action_server",
    "SimpleActionServer": "simple_action_server",
}


#: ROS 1's ``import actionlib`` loads these modules; here they load when first reached
_SUBMODULES = {
    "action_client",
    "action_server",
    "exceptions",
    "goal_id_generator",
    "handle_tracker_deleter",
    "server_goal_handle",
    "simple_action_client",
    "simple_action_server",
    "status_tracker",
}


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"actionlib.{name}")  # the import binds it in this namespace
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'actionlib' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"actionlib.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS, *_SUBMODULES})
