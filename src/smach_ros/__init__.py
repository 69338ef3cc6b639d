"""smach_ros as provided by ninjemys: smach states that talk to ROS, and the introspection server.

As in ROS 1, importing smach_ros routes smach's log lines through rospy (console, log file, /rosout)
and makes containers stop when rospy shuts down. The states run on the node of ``rospy.init_node``.
"""

import rospy
import smach
from smach_ros.action_server_wrapper import ActionServerWrapper
from smach_ros.condition_state import ConditionState
from smach_ros.introspection import IntrospectionClient, IntrospectionServer
from smach_ros.monitor_state import MonitorState
from smach_ros.service_state import ServiceState
from smach_ros.simple_action_state import SimpleActionState
from smach_ros.util import set_preempt_handler

smach.set_loggers(rospy.loginfo, rospy.logwarn, rospy.logdebug, rospy.logerr)
smach.set_shutdown_check(rospy.is_shutdown)

__all__ = [
    "ActionServerWrapper",
    "ConditionState",
    "IntrospectionClient",
    "IntrospectionServer",
    "MonitorState",
    "ServiceState",
    "SimpleActionState",
    "set_preempt_handler",
]
