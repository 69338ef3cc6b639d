"""rosbridge v2 acceptance with roslibpy (from PyPI, a client nobody here wrote) against the gateway."""

from __future__ import annotations

import subprocess
import textwrap
import threading
import time
from collections.abc import Iterator

import pytest

from ninjemys.bridge.rosapi import RosApi
from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node import Node
from ninjemys.testing import ros1_env, wait_until

roslibpy = pytest.importorskip("roslibpy")

String = get_message_class("std_msgs/String")
Image = get_message_class("sensor_msgs/Image")
AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")


@pytest.fixture
def ros(gateway: Gateway) -> Iterator[object]:
    client = roslibpy.Ros("127.0.0.1", gateway.port)
    client.run(timeout=10)
    yield client
    client.close()


@pytest.fixture
def rosapi(master_uri: str) -> Iterator[RosApi]:
    node = Node("rosapi", master_uri=master_uri)
    api = RosApi(node)
    yield api
    api.shutdown()
    node.shutdown("test over")


def test_topics_both_ways(ros: object, node: Node) -> None:
    got: list[str] = []
    node.subscriber("/from_browser", String, lambda m: got.append(m.data))
    pub = node.publisher("/to_browser", Image)
    received: list[dict] = []
    roslibpy.Topic(ros, "/to_browser", "sensor_msgs/Image").subscribe(received.append)
    out = roslibpy.Topic(ros, "/from_browser", "std_msgs/String")
    out.advertise()
    wait_until(lambda: pub.get_num_connections() > 0, what="the gateway subscribing")
    wait_until(
        lambda: node.get_subscriptions() and len(node.master.get_system_state()[0]) >= 2, what="advertise"
    )
    image = Image(height=1, width=2, encoding="rgb8", step=6, data=bytes(range(6)))
    image.header.stamp.secs, image.header.stamp.nsecs = 12, 345
    image.header.frame_id = "camera"
    pub.publish(image)

    def sent() -> bool:
        out.publish(roslibpy.Message({"data": "hello from roslibpy"}))
        return bool(got)

    wait_until(sent, what="roslibpy -> ROS")
    wait_until(lambda: received, what="ROS -> roslibpy")
    msg = received[0]
    # rosbridge's JSON: uint8[] as base64, time as {secs, nsecs}
    assert msg["data"] == "AAECAwQF"
    assert msg["header"]["stamp"] == {"secs": 12, "nsecs": 345}
    assert msg["header"]["frame_id"] == "camera" and msg["encoding"] == "rgb8"
    assert got[0] == "hello from roslibpy"


def test_call_and_advertise_services(ros: object, node: Node) -> None:
    node.service("/add_two_ints", AddTwoInts, lambda r: r.a + r.b)
    service = roslibpy.Service(ros, "/add_two_ints", "rospy_tutorials/AddTwoInts")
    assert service.call(roslibpy.ServiceRequest({"a": 40, "b": 2}), timeout=10) == {"sum": 42}

    def handler(request: dict, response: dict) -> bool:
        response["sum"] = request["a"] * request["b"]
        return True

    provided = roslibpy.Service(ros, "/ws_multiply", "rospy_tutorials/AddTwoInts")
    provided.advertise(handler)
    node.wait_for_service("/ws_multiply", timeout=10)
    proxy = node.service_proxy("/ws_multiply", AddTwoInts)
    assert proxy(6, 7).sum == 42
    # a failing call comes back as a failed service_response, not a hang
    missing = roslibpy.Service(ros, "/no_such_service", "rospy_tutorials/AddTwoInts")
    with pytest.raises(Exception, match="no_such_service|does not exist"):
        missing.call(roslibpy.ServiceRequest({"a": 1, "b": 2}), timeout=10)


def test_parameters_and_rosapi(ros: object, node: Node, rosapi: RosApi) -> None:
    node.wait_for_service("/rosapi/get_param", timeout=10)
    node.set_param("/robot/max_speed", 1.5)
    assert ros.get_param("/robot/max_speed") == 1.5
    ros.set_param("/robot/name", "puzzlebot")
    assert node.get_param("/robot/name") == "puzzlebot"
    ros.set_param("/robot/gains", [1, 2, 3])
    assert node.get_param("/robot/gains") == [1, 2, 3]
    assert "/robot/name" in ros.get_params()
    node.publisher("/chatter", String)
    wait_until(lambda: "/chatter" in ros.get_topics(), what="rosapi topics")
    assert ros.get_topic_type("/chatter") == "std_msgs/String"
    assert "/chatter" in ros.get_topics_for_type("std_msgs/String")
    assert node.name in ros.get_nodes()
    assert "/rosapi/get_param" in ros.get_services()
    assert ros.get_service_type("/rosapi/get_param") == "rosapi/GetParam"
    details = ros.get_message_details("geometry_msgs/PoseStamped")
    types = [d["type"] for d in details["typedefs"]]
    assert types[0] == "geometry_msgs/PoseStamped" and "std_msgs/Header" in types and "time" in types
    pose = details["typedefs"][0]
    assert pose["fieldnames"] == ["header", "pose"] and pose["fieldarraylen"] == [-1, -1]
    node_details = ros.get_node_details(node.name)
    assert "/chatter" in node_details["publishing"]
    t = ros.get_time()
    assert t["secs"] > 1_600_000_000


def test_tf_through_tfclient(ros: object, master_uri: str) -> None:
    pytest.importorskip("ninjemys.tf2.node")
    from roslibpy.tf import TFClient

    from ninjemys.bridge.tf_republisher import TFRepublisher
    from ninjemys.tf2.node import TransformBroadcaster

    tf_node = Node("tf2_web_republisher", master_uri=master_uri)
    republisher = TFRepublisher(tf_node)
    try:
        broadcaster = TransformBroadcaster(tf_node)
        Stamped = get_message_class("geometry_msgs/TransformStamped")
        frames: list[dict] = []
        client = TFClient(ros, fixed_frame="world", rate=10.0, angular_threshold=0.01)
        client.subscribe("base_link", frames.append)

        def broadcast(x: float = 1.25) -> bool:
            t = Stamped()
            t.header.frame_id, t.child_frame_id = "world", "base_link"
            t.transform.translation.x = x
            t.transform.rotation.w = 1.0
            broadcaster.sendTransform(t)
            return bool(frames)

        wait_until(broadcast, timeout=20, what="a transform through the TFClient")
        assert frames[0]["translation"]["x"] == pytest.approx(1.25)

        # the action interface (TFSubscription): transforms come as the goal's feedback
        from roslibpy.ros1.actionlib import ActionClient, Goal

        client = ActionClient(ros, "/tf2_web_republisher", "tf2_web_republisher/TFSubscriptionAction")
        feedback: list[dict] = []
        request = {
            "source_frames": ["base_link"],
            "target_frame": "world",
            "angular_thres": 0.01,
            "trans_thres": 0.01,
            "rate": 10.0,
        }
        goals: list = []

        def subscribed() -> bool:
            # a goal published before the gateway's goal publisher connected is lost (as with any
            # ROS 1 publisher): send a new one until one is answered
            if not feedback and (not goals or time.monotonic() - goals[-1][1] > 2.0):
                goal = Goal(client, roslibpy.Message(request))
                goal.on("feedback", feedback.append)
                goal.send()
                goals.append((goal, time.monotonic()))
            broadcast()
            return bool(feedback)

        wait_until(subscribed, timeout=30, what="TFSubscription feedback")
        goal = goals[-1][0]
        transform = feedback[0]["transforms"][0]
        assert transform["header"]["frame_id"] == "world" and transform["child_frame_id"] == "base_link"
        goal.cancel()
        wait_until(
            lambda: goal.status and goal.status["status"] == 2,
            timeout=20,
            what="the goal cancelled (PREEMPTED)",
        )
        # the service's subscription keeps flowing after the goal ended
        wait_until(
            lambda: broadcast(2.5) and frames[-1]["translation"]["x"] == pytest.approx(2.5),
            timeout=20,
            what="TFClient updates after the goal's end",
        )
    finally:
        republisher.shutdown()
        tf_node.shutdown("test over")


ACTION_SERVER = textwrap.dedent(
    """
    import rospy, actionlib
    from tf2_msgs.msg import LookupTransformAction, LookupTransformResult
    rospy.init_node("lookup_server")
    def execute(goal):
        result = LookupTransformResult()
        result.transform.header.frame_id = goal.target_frame
        result.transform.child_frame_id = goal.source_frame
        server.set_succeeded(result)
    server = actionlib.SimpleActionServer("/lookup", LookupTransformAction, execute, auto_start=False)
    server.start()
    rospy.spin()
    """
)


@pytest.mark.ros1
def test_actionlib_goal_through_roslibpy(ros: object, master_uri: str, rosapi: RosApi, tmp_path) -> None:
    """roslibpy's ROS 1 ActionClient drives Debian's actionlib SimpleActionServer through the gateway."""
    from roslibpy.ros1.actionlib import ActionClient, Goal

    script = tmp_path / "server.py"
    script.write_text(ACTION_SERVER)
    proc = subprocess.Popen(["/usr/bin/python3", str(script)], env=ros1_env(master_uri))
    try:
        wait_until(lambda: "/lookup/goal" in ros.get_topics(), timeout=30, what="the actionlib server")
        client = ActionClient(ros, "/lookup", "tf2_msgs/LookupTransformAction")
        done = threading.Event()
        results: list[dict] = []

        def attempt() -> bool:
            goal = Goal(client, roslibpy.Message({"target_frame": "map", "source_frame": "base_link"}))
            goal.on("result", lambda r: (results.append(r), done.set()))
            goal.send()
            return done.wait(2.0)

        wait_until(attempt, timeout=30, what="the goal's result")
        assert results[0]["transform"]["header"]["frame_id"] == "map"
        assert results[0]["transform"]["child_frame_id"] == "base_link"
    finally:
        proc.terminate()
        proc.wait(10)


def test_actionlib_goal_with_feedback_against_ninjemys_actionlib(
    ros: object, master_uri: str, rosapi: RosApi
) -> None:
    """roslibpy's ROS 1 ActionClient against our SimpleActionServer: feedback, then the result."""
    from roslibpy.ros1.actionlib import ActionClient, Goal

    from ninjemys.actionlib.simple_server import SimpleActionServer

    Fibonacci = get_message_class("actionlib_tutorials/FibonacciAction")
    Feedback = get_message_class("actionlib_tutorials/FibonacciFeedback")
    Result = get_message_class("actionlib_tutorials/FibonacciResult")
    server_node = Node("fibonacci", master_uri=master_uri)

    def execute(goal: object) -> None:
        seq = [0, 1]
        for _ in range(1, goal.order):
            seq.append(seq[-1] + seq[-2])
            server.publish_feedback(Feedback(sequence=seq))
            time.sleep(0.05)
        server.set_succeeded(Result(sequence=seq))

    server = SimpleActionServer(server_node, "/fibonacci", Fibonacci, execute)
    server.start()
    try:
        wait_until(lambda: "/fibonacci/goal" in ros.get_topics(), timeout=30, what="the action server")
        client = ActionClient(ros, "/fibonacci", "actionlib_tutorials/FibonacciAction")
        done = threading.Event()
        results: list[dict] = []
        feedback: list[dict] = []

        def attempt() -> bool:
            # the gateway's subscriptions to feedback/result connect while the first goals run:
            # retry until one goal was seen whole
            done.clear()
            feedback.clear()
            goal = Goal(client, roslibpy.Message({"order": 6}))
            goal.on("feedback", feedback.append)
            goal.on("result", lambda r: (results.append(r), done.set()))
            goal.send()
            return done.wait(3.0) and len(feedback) == 5

        wait_until(attempt, timeout=30, what="the goal's result")
        assert results[0]["sequence"] == [0, 1, 1, 2, 3, 5, 8]
        assert feedback and feedback[-1]["sequence"][:3] == [0, 1, 1]
    finally:
        server.stop()
        server_node.shutdown("test over")


def test_a_ros_caller_is_released_when_the_providing_client_leaves(gateway: Gateway, node: Node) -> None:
    from websockets.sync.client import connect

    from ninjemys.errors import ServiceError

    errors: list[str] = []

    def call() -> None:
        try:
            node.service_proxy("/ws_slow", AddTwoInts)(1, 2)
        except ServiceError as exc:
            errors.append(str(exc))

    caller = threading.Thread(target=call)
    with connect(f"ws://127.0.0.1:{gateway.port}/") as ws:
        ws.send('{"op": "advertise_service", "service": "/ws_slow", "type": "rospy_tutorials/AddTwoInts"}')
        node.wait_for_service("/ws_slow", timeout=10)
        caller.start()
        # the request reaches the client, which leaves without answering
        assert '"call_service"' in ws.recv(timeout=10)
    caller.join(10)
    assert not caller.is_alive() and "went away" in errors[0]
