"""smach, the ROS 1 task-level state machine library, as provided by ninjemys (``import smach``).

Re-exports :mod:`ninjemys.smach`, which holds the implementation; names follow executive_smach 2.5.
"""

from ninjemys.smach.concurrence import Concurrence
from ninjemys.smach.container import Container
from ninjemys.smach.errors import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
    SmachError,
)
from ninjemys.smach.iterator import Iterator
from ninjemys.smach.log import (
    is_shutdown,
    logdebug,
    logerr,
    loginfo,
    logwarn,
    set_loggers,
    set_shutdown_check,
)
from ninjemys.smach.sequence import Sequence
from ninjemys.smach.state import CBInterface, CBState, State, cb_interface, has_smach_interface
from ninjemys.smach.state_machine import StateMachine
from ninjemys.smach.userdata import Remapper, UserData

__all__ = [
    "CBInterface",
    "CBState",
    "Concurrence",
    "Container",
    "InvalidConstructionError",
    "InvalidStateError",
    "InvalidTransitionError",
    "InvalidUserCodeError",
    "Iterator",
    "Remapper",
    "Sequence",
    "SmachError",
    "State",
    "StateMachine",
    "UserData",
    "cb_interface",
    "has_smach_interface",
    "is_shutdown",
    "logdebug",
    "logerr",
    "loginfo",
    "logwarn",
    "set_loggers",
    "set_shutdown_check",
]
