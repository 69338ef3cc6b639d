"""The Node owns its lifecycle: its clock (wall or /clock), its logging and /rosout, its logger services."""

from __future__ import annotations

import threading
import xmlrpc.client

import pytest

from ninjemys import rostime
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.testing import FakeClock, wait_until

ClockMsg = get_message_class("rosgraph_msgs/Clock")
Log = get_message_class("rosgraph_msgs/Log")


def _stamp(ns: int) -> rostime.Time:
    return rostime.Time(ns // 1_000_000_000, ns % 1_000_000_000)


def test_two_nodes_in_one_process_follow_their_own_time(make_node) -> None:
    sim = make_node("sim_node", sim_time=True, default_clock=True)
    wall = make_node("wall_node", sim_time=False)
    assert sim.clock.is_sim and wall.clock.is_wallclock
    assert sim.get_time() == 0.0 and wall.get_time() > 1.6e9  # ROS 1: 0 until the first /clock

    clock_pub = wall.publisher("/clock", ClockMsg, queue_size=None)
    assert wait_until(lambda: clock_pub.get_num_connections() == 1)
    now_ns = 100 * 1_000_000_000

    def tick(ns: int) -> None:
        clock_pub.publish(ClockMsg(clock=_stamp(ns)))
        assert wait_until(lambda: sim.clock.now_ns() == ns)

    tick(now_ns)
    assert sim.now() == rostime.Time(100) and sim.get_time() == 100.0
    assert rostime.Time.now() == rostime.Time(100)  # the process default follows the sim node

    sim_events: list = []
    wall_events: list = []
    sim_timer = sim.timer(0.5, sim_events.append)
    wall_timer = wall.timer(0.01, wall_events.append)
    sim_loop_times: list[float] = []
    wall_loop_times: list[float] = []

    def sim_loop() -> None:
        rate = sim.rate(10)
        for _ in range(5):
            rate.sleep()
            sim_loop_times.append(sim.get_time())

    loop = threading.Thread(target=sim_loop)
    loop.start()
    wall_rate = wall.rate(200)
    for _ in range(5):
        wall_rate.sleep()
        wall_loop_times.append(wall.get_time())
    # wall time moved on, /clock did not: the wall node's Rate and Timer ran, the sim node's did not
    assert wait_until(lambda: len(wall_events) >= 3)
    assert sim_loop_times == [] and sim_events == [] and sim.get_time() == 100.0
    assert all(t > 1.6e9 for t in wall_loop_times) and wall_loop_times == sorted(wall_loop_times)
    assert all(ev.current_real.to_sec() > 1.6e9 for ev in wall_events[:3])

    while loop.is_alive() and now_ns < 110 * 1_000_000_000:
        now_ns += 50_000_000  # 0.05 s of simulated time per /clock message
        tick(now_ns)
        loop.join(0.001)
    loop.join(5.0)
    assert not loop.is_alive()
    assert len(sim_loop_times) == 5 and sim_loop_times == sorted(sim_loop_times)
    assert 100.1 - 1e-9 <= sim_loop_times[0] and sim_loop_times[-1] < 110.0
    assert wait_until(lambda: len(sim_events) >= 1)
    assert sim_events[0].current_expected == rostime.Time(100, 500_000_000)
    assert 100.5 <= sim_events[0].current_real.to_sec() < 110.0
    sim_timer.shutdown()
    wall_timer.shutdown()


def test_use_sim_time_auto_and_explicit_choice(make_node, master) -> None:
    xmlrpc.client.ServerProxy(master.uri).setParam("/test", "/use_sim_time", True)
    auto = make_node("auto_node")
    forced_wall = make_node("wall_node", sim_time=False)
    assert auto.clock.is_sim and auto.get_time() == 0.0
    assert forced_wall.clock.is_wallclock
    assert "/clock" in dict(auto.get_subscriptions())
    assert "/clock" not in dict(forced_wall.get_subscriptions())
    with pytest.raises(ValueError, match="sim_time"):
        Node("bad", master_uri=master.uri, sim_time="yes")


def test_a_fake_clock_drives_a_node_by_hand(make_node) -> None:
    clock = FakeClock(5.0)
    node = make_node("driven", clock=clock, default_clock=False)
    assert node.clock is clock and node.now() == rostime.Time(5)
    assert "/clock" not in dict(node.get_subscriptions())
    fired = threading.Event()
    node.timer(1.0, lambda ev: fired.set(), oneshot=True)
    assert not fired.wait(0.05)
    clock.advance(1.0)
    assert fired.wait(5.0)


def test_first_node_is_the_process_default_clock(make_node) -> None:
    assert rostime.default_clock_owner() is None
    first = make_node("first", clock=FakeClock(42.0))
    second = make_node("second", sim_time=False)
    assert rostime.default_clock_owner() is first
    assert rostime.Time.now() == rostime.Time(42)
    first.shutdown("done")
    assert rostime.default_clock_owner() is None  # back to wall time, not handed to a later node
    assert rostime.Time.now().to_sec() > 1.6e9
    assert second.now().to_sec() > 1.6e9


def test_shutdown_wakes_the_nodes_sleepers_only(make_node) -> None:
    a = make_node("sleeper_a", sim_time=True)
    b = make_node("sleeper_b", sim_time=True)
    errors: list[BaseException] = []

    def sleep_on_a() -> None:
        try:
            a.sleep(10.0)
        except BaseException as exc:  # ShutdownError expected
            errors.append(exc)

    sleeper = threading.Thread(target=sleep_on_a)
    sleeper.start()
    a.shutdown("test")
    sleeper.join(5.0)
    assert not sleeper.is_alive() and type(errors[0]).__name__ == "ShutdownError"
    assert not b.clock.is_shutdown


def test_logger_services_are_registered_when_the_node_returns(make_node, master) -> None:
    api = xmlrpc.client.ServerProxy(master.uri)
    node = make_node("logged")
    # no wait: Node() returns after the master knows both services (as rospy.init_node in ROS 1)
    assert api.lookupService("/test", "/logged/get_loggers")[0] == 1
    assert api.lookupService("/test", "/logged/set_logger_level")[0] == 1
    caller = make_node("caller", rosout=False, logger_services=False)
    get = caller.service_proxy("/logged/get_loggers", get_service_class("roscpp/GetLoggers"))
    levels = {logger.name: logger.level for logger in get().loggers}
    assert levels["rosout"] == "info"
    caller.service_proxy("/logged/set_logger_level", get_service_class("roscpp/SetLoggerLevel"))(
        logger="rosout", level="debug"
    )
    assert node.log.level == 1
    assert api.lookupService("/test", "/caller/get_loggers")[0] != 1
    assert "/rosout" not in dict(caller.get_publications())


def test_node_log_reaches_rosout_with_its_name(make_node) -> None:
    talker = make_node("talker")
    listener = make_node("listener", rosout=False)
    got: list = []
    seen = threading.Event()

    def on_log(msg) -> None:
        if msg.name == "/talker" and msg.msg == "hello 7":
            got.append(msg)
            seen.set()

    listener.subscriber("/rosout", Log, on_log)
    assert wait_until(lambda: talker.get_publications() and _rosout_connections(talker) >= 2)
    talker.log.info("hello %d", 7)
    assert seen.wait(5.0)
    assert got[0].level == 2 and "/rosout" in got[0].topics


def _rosout_connections(node: Node) -> int:
    return sum(1 for entry in node.bus_info() if entry[4] == "/rosout")


def test_a_core_node_follows_rosbag_play_clock(make_node, master, tmp_path) -> None:
    """``Node(...)`` with the default ``sim_time="auto"`` just works under ``rosbag play --clock``."""
    import os
    import struct
    import subprocess

    from ninjemys.bag.writer import BagWriter
    from ninjemys.testing import ninjemys_bin

    base = 1_700_000_000 * 1_000_000_000
    bag = tmp_path / "clocked.bag"
    header = {
        "type": b"std_msgs/String",
        "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
        "message_definition": b"string data\n",
    }
    with BagWriter(bag) as writer:
        conn = writer.connection("/chatter", header)
        for i in range(40):
            text = f"bag {i}".encode()
            writer.write(conn, base + i * 50_000_000, struct.pack("<I", len(text)) + text)
    xmlrpc.client.ServerProxy(master.uri).setParam("/test", "/use_sim_time", True)
    node = make_node("bag_consumer")
    assert node.clock.is_sim and node.get_time() == 0.0
    stamps: list[tuple[str, int]] = []
    ticks: list = []
    node.subscriber(
        "/chatter",
        get_message_class("std_msgs/String"),
        lambda m: stamps.append((m.data, node.clock.now_ns())),
    )
    node.timer(0.5, ticks.append)
    env = dict(os.environ, ROS_MASTER_URI=master.uri, ROS_HOSTNAME="localhost")
    player = subprocess.run(
        [ninjemys_bin("rosbag"), "play", "--clock", "-d", "1.0", "-q", str(bag)],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert player.returncode == 0, player.stderr
    assert wait_until(lambda: len(stamps) >= 30)
    # the node's time is the bag's: every message arrives at (about) its recorded time, not wall time
    assert all(base <= ns <= base + 3 * 1_000_000_000 for _, ns in stamps)
    assert ticks and all(base / 1e9 <= ev.current_expected.to_sec() <= base / 1e9 + 3 for ev in ticks), [
        ev.current_expected for ev in ticks
    ]
