"""actionlib's core: action servers and clients on a :class:`ninjemys.node.Node`, with ROS 1's protocol.

No rospy here: the ``actionlib`` facade (``import actionlib``) binds these classes to the process's
node. ``states`` holds the protocol's state vocabularies and the client's transition table,
``goal_id`` the goal id formats, ``server``/``client`` the two ends, ``simple_server``/
``simple_client`` the one-goal-at-a-time layers most code uses.
"""

from ninjemys.actionlib.client import ActionClient, ClientGoalHandle, CommStateMachine
from ninjemys.actionlib.goal_id import GoalIDGenerator
from ninjemys.actionlib.server import ActionServer, ServerGoalHandle, StatusTracker
from ninjemys.actionlib.simple_client import SimpleActionClient
from ninjemys.actionlib.simple_server import SimpleActionServer
from ninjemys.actionlib.states import CommState, SimpleGoalState, TerminalState

__all__ = [
    "ActionClient",
    "ActionServer",
    "ClientGoalHandle",
    "CommState",
    "CommStateMachine",
    "GoalIDGenerator",
    "ServerGoalHandle",
    "SimpleActionClient",
    "SimpleActionServer",
    "SimpleGoalState",
    "StatusTracker",
    "TerminalState",
]
