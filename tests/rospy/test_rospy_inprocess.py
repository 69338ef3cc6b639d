"""rospy in the test's own process: ``ninjemys.testing.reset_rospy()`` lets each test call init_node afresh.

These used to run a node process each (see test_rospy_nodes.py for the ones that need a process:
signals, exit codes, console output).
"""

from __future__ import annotations

import threading
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import rostime
from ninjemys.testing import reset_rospy


@pytest.fixture
def rospy_env(master: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Iterator[str]:
    """The environment of a node process, in-process; rospy's state is reset afterwards."""
    for key in ("ROS_NAMESPACE", "ROS_LOG_DIR", "ROSCONSOLE_FORMAT", "ROS_IP"):
        monkeypatch.delenv(key, raising=False)
    monkeypatch.setenv("ROS_MASTER_URI", master)
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    reset_rospy()
    try:
        yield master
    finally:
        reset_rospy()


def test_reset_allows_a_new_init_node(rospy_env: str) -> None:
    import rospy

    hooks: list[str] = []
    rospy.init_node("first", argv=["first"], disable_signals=True)
    rospy.on_shutdown(lambda: hooks.append("first down"))
    assert rospy.get_name() == "/first" and rospy.core.is_initialized()
    reset_rospy()
    assert hooks == ["first down"]  # user hooks ran, as on a real shutdown
    assert rospy.get_name() == "/unnamed" and not rospy.is_shutdown()
    rospy.init_node("second", argv=["second"], disable_signals=True)
    assert rospy.get_name() == "/second" and not rospy.is_shutdown()
    state = xmlrpc.client.ServerProxy(rospy_env).getSystemState("/test")[2]
    nodes = {n for group in state for _name, members in group for n in members}
    assert "/second" in nodes and "/first" not in nodes


def test_logger_services_are_registered_when_init_node_returns(rospy_env: str) -> None:
    import rospy
    from roscpp.srv import GetLoggers, SetLoggerLevel

    rospy.init_node("target", argv=["target"], disable_signals=True)
    api = xmlrpc.client.ServerProxy(rospy_env)
    # ROS 1: init_node returns once the master knows the node's logger services (no waiting here)
    assert api.lookupService("/test", "/target/get_loggers")[0] == 1
    assert api.lookupService("/test", "/target/set_logger_level")[0] == 1
    get = rospy.ServiceProxy("/target/get_loggers", GetLoggers)
    assert {lg.name: lg.level for lg in get().loggers}["rosout"] == "info"
    rospy.ServiceProxy("/target/set_logger_level", SetLoggerLevel)("rosout", "debug")
    assert {lg.name: lg.level for lg in get().loggers}["rosout"] == "debug"
    with pytest.raises(rospy.ServiceException, match="bogus"):
        rospy.ServiceProxy("/target/set_logger_level", SetLoggerLevel)("rosout", "bogus")


def test_sim_time_follows_clock_and_pre_init_rate_switches(rospy_env: str) -> None:
    import rospy
    from rosgraph_msgs.msg import Clock

    xmlrpc.client.ServerProxy(rospy_env).setParam("/x", "/use_sim_time", True)
    try:
        early_rate = rospy.Rate(1)  # made before init_node, on the wall clock: must follow /clock after
        rospy.init_node("simnode", argv=["simnode"], disable_signals=True)
        assert rospy.get_time() == 0.0 and rospy.Time.now() == rospy.Time(0)
        assert not rospy.rostime.is_wallclock()
        pub = rospy.Publisher("/clock", Clock, queue_size=10)
        woke = threading.Event()
        sleeps_done = threading.Event()

        def sleeper() -> None:
            rospy.sleep(5.0)
            woke.set()
            early_rate.sleep()
            early_rate.sleep()
            sleeps_done.set()

        threading.Thread(target=sleeper, daemon=True).start()
        t = 100
        while not sleeps_done.is_set() and t < 200:
            pub.publish(Clock(clock=rospy.Time(t)))
            t += 1
            sleeps_done.wait(0.02)
        assert woke.is_set() and sleeps_done.is_set()
        assert 105.0 <= rospy.get_time() < 200 and rostime.Time.now().to_sec() >= 105.0
    finally:
        xmlrpc.client.ServerProxy(rospy_env).setParam("/x", "/use_sim_time", False)


def test_params_timer_and_wait_for_message(rospy_env: str) -> None:
    import rospy
    from std_msgs.msg import String

    rospy.init_node("checker", argv=["checker", "_gain:=2.5"], disable_signals=True)
    assert rospy.get_param("~gain") == 2.5
    rospy.set_param("~p", {"a": 1, "b": [1, 2]})
    assert rospy.get_param("~p/a") == 1 and rospy.get_param("missing", 42) == 42
    with pytest.raises(KeyError):
        rospy.get_param("/not/set")
    fired = threading.Event()
    events: list = []

    def tick(event: rospy.timer.TimerEvent) -> None:
        events.append(event)
        fired.set()

    rospy.Timer(rospy.Duration(0.05), tick, oneshot=True)
    assert fired.wait(5)
    assert type(events[0]).__name__ == "TimerEvent" and events[0].current_real > rospy.Time(0)
    pub = rospy.Publisher("latched", String, queue_size=1, latch=True)
    pub.publish(data="kw")
    assert rospy.wait_for_message("latched", String, timeout=5).data == "kw"
    with pytest.raises(rospy.ROSException, match="timeout exceeded"):
        rospy.wait_for_message("silent", String, timeout=0.2)


def test_publisher_made_before_init_node_binds_to_the_node(rospy_env: str) -> None:
    import rospy
    from std_msgs.msg import String

    pub = rospy.Publisher("early", String, queue_size=1)
    rospy.init_node("early_bird", argv=["early_bird"], disable_signals=True)
    assert ["/early", "std_msgs/String"] in rospy.core.process_node().get_publications()
    got = threading.Event()
    sub = rospy.Subscriber("early", String, lambda msg: got.set())
    while not got.is_set() and not rospy.is_shutdown():
        pub.publish("hello")
        got.wait(0.05)
    sub.unregister()
    assert got.is_set()


def test_publish_fast_path_keeps_rospy_errors_and_the_no_subscriber_rule(rospy_env: str) -> None:
    """rospy.Publisher.publish takes a message of the topic's own class by a shorter path (issue 25);
    it still serializes nothing without a subscriber, delivers with one, and turns a bad field into
    ROSSerializationException; other arguments still take the general path."""
    import rospy
    from ninjemys.testing import wait_until
    from std_msgs.msg import String

    rospy.init_node("fast", argv=["fast"], disable_signals=True)
    pub = rospy.Publisher("/fast", String, queue_size=10)
    pub.publish(String(data=5))  # nobody listens: not serialized, no error (as rospy)
    got: list[str] = []
    rospy.Subscriber("/fast", String, lambda m: got.append(m.data))
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(String(data="hello"))
    assert wait_until(lambda: got == ["hello"])
    with pytest.raises(rospy.ROSSerializationException, match="data"):
        pub.publish(String(data=5))
    pub.publish("built")  # arguments still build the message (the general path)
    assert wait_until(lambda: got == ["hello", "built"])
