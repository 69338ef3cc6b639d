"""rospy, the ROS 1 Python client API, as a thin facade over ninjemys' core node runtime.

Programs written for rospy run unmodified::

    import rospy
    from std_msgs.msg import String

    pub = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        pub.publish("hello world %s" % rospy.get_time())
        rate.sleep()

The behaviour lives in ``ninjemys.node`` (transport, logging, clock, timers, command-line arguments);
this package only keeps rospy's one piece of global state, "the node of this process", and maps
ninjemys errors onto rospy's exceptions. Importing it is cheap: the node runtime is loaded by
``init_node``.
"""

from __future__ import annotations

from ninjemys.rostime import Duration, Time
from rospy.client import (
    delete_param,
    get_caller_id,
    get_master,
    get_name,
    get_namespace,
    get_param,
    get_param_cached,
    get_param_names,
    get_published_topics,
    has_param,
    init_node,
    myargv,
    remap_name,
    resolve_name,
    search_param,
    set_param,
    spin,
    wait_for_message,
)
from rospy.core import (
    DEBUG,
    ERROR,
    FATAL,
    INFO,
    WARN,
    get_node_uri,
    is_initialized,
    is_shutdown,
    logdebug,
    logdebug_once,
    logdebug_throttle,
    logdebug_throttle_identical,
    logerr,
    logerr_once,
    logerr_throttle,
    logerr_throttle_identical,
    logerror,
    logfatal,
    logfatal_once,
    logfatal_throttle,
    logfatal_throttle_identical,
    loginfo,
    loginfo_once,
    loginfo_throttle,
    loginfo_throttle_identical,
    logout,
    logwarn,
    logwarn_once,
    logwarn_throttle,
    logwarn_throttle_identical,
    on_shutdown,
    signal_shutdown,
)
from rospy.exceptions import (
    ROSException,
    ROSInitException,
    ROSInternalException,
    ROSInterruptException,
    ROSSerializationException,
    ROSTimeMovedBackwardsException,
    ServiceException,
)
from rospy.msg import AnyMsg
from rospy.rostime import get_rostime, get_time
from rospy.service import Service, ServiceProxy, wait_for_service
from rospy.timer import Rate, Timer, TimerEvent, sleep
from rospy.topics import Publisher, SubscribeListener, Subscriber


def _install_import_hook() -> None:
    """``from my_pkg.msg import MyMsg`` for packages on ROS_PACKAGE_PATH, without a build step; and
    Noetic's ``URDF.from_parameter_server()`` on the PyPI urdf_parser_py (see rospy._urdf)."""
    from ninjemys.idl.hook import install
    from rospy import _urdf

    install()
    _urdf.install()


_install_import_hook()

__all__ = [
    "AnyMsg",
    "DEBUG",
    "Duration",
    "ERROR",
    "FATAL",
    "INFO",
    "Header",
    "Publisher",
    "ROSException",
    "ROSInitException",
    "ROSInternalException",
    "ROSInterruptException",
    "ROSSerializationException",
    "ROSTimeMovedBackwardsException",
    "Rate",
    "Service",
    "ServiceException",
    "ServiceProxy",
    "SubscribeListener",
    "Subscriber",
    "Time",
    "Timer",
    "TimerEvent",
    "WARN",
    "delete_param",
    "get_caller_id",
    "get_master",
    "get_name",
    "get_namespace",
    "get_node_uri",
    "get_param",
    "get_param_cached",
    "get_param_names",
    "get_published_topics",
    "get_rostime",
    "get_time",
    "has_param",
    "init_node",
    "is_initialized",
    "is_shutdown",
    "logdebug",
    "logdebug_once",
    "logdebug_throttle",
    "logdebug_throttle_identical",
    "logerr",
    "logerr_once",
    "logerr_throttle",
    "logerr_throttle_identical",
    "logerror",
    "logfatal",
    "logfatal_once",
    "logfatal_throttle",
    "logfatal_throttle_identical",
    "loginfo",
    "loginfo_once",
    "loginfo_throttle",
    "loginfo_throttle_identical",
    "logout",
    "logwarn",
    "logwarn_once",
    "logwarn_throttle",
    "logwarn_throttle_identical",
    "myargv",
    "numpy_msg",
    "on_shutdown",
    "remap_name",
    "resolve_name",
    "search_param",
    "set_param",
    "signal_shutdown",
    "sleep",
    "spin",
    "wait_for_message",
    "wait_for_service",
]


def __getattr__(name: str) -> object:
    """``rospy.Header`` and ``rospy.numpy_msg`` load their modules on first use only."""
    if name == "Header":
        from std_msgs.msg import Header

        return Header
    if name == "names":  # rospy imports rospy.names eagerly; code reads rospy.names.get_namespace()
        import importlib

        return importlib.import_module("rospy.names")
    if name == "numpy_msg":
        import importlib  # not "from rospy import numpy_msg": that asks this __getattr__ again

        return importlib.import_module("rospy.numpy_msg")
    raise AttributeError(f"module 'rospy' has no attribute {name!r}")
